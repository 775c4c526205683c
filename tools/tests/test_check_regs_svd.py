"""scripts/check_regs_svd.py finds a register definition that ST's SVD files
contradict (a bit, an offset, an interrupt number, a field's value) and one
it cannot judge; and it passes the ports' headers as they are."""
import importlib.util
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("check_regs_svd", ROOT / "scripts/check_regs_svd.py")
check_regs_svd = importlib.util.module_from_spec(spec)
spec.loader.exec_module(check_regs_svd)

F1 = "STM32F103xx"
F0 = "STM32F030"
G0 = "STM32G031"
# No package ships ST's STM32G031.svd: the G0's cases run where a folder
# holds it ($SERVO_SVD_DIR).
G0_SVD = check_regs_svd.svd_file(G0)
needs_g0_svd = pytest.mark.skipif(G0_SVD is None, reason="no STM32G031.svd ($SERVO_SVD_DIR)")


def ports_with(tmp_path, rel, old, new):
    shutil.copytree(ROOT / "hal/ports", tmp_path / "ports")
    path = tmp_path / "ports" / rel
    text = path.read_text()
    assert old in text, f"{old!r} is not in {rel}: the test needs updating"
    path.write_text(text.replace(old, new))
    return tmp_path / "ports"


@pytest.mark.parametrize("part", [F1, F0])
def test_the_ports_headers_match_the_svd(part):
    assert check_regs_svd.check_part(part, ROOT / "hal/ports") == []


@pytest.mark.parametrize("rel, old, new, part, name", [
    # a bit one place off
    ("stm32f1/stm32f1_regs.h", "USART_SR_RXNE (1u << 5)", "USART_SR_RXNE (1u << 4)", F1, "USART_SR_RXNE"),
    # a register at the wrong offset
    ("stm32f0/stm32f0_regs.h", "USART_ISR(b) REG32((b) + 0x1Cu)", "USART_ISR(b) REG32((b) + 0x18u)", F0,
     "USART_ISR"),
    # the shared header wrong for one part only: judged against both
    ("stm32_common/stm32_core_regs.h", "RCC_APB1ENR_TIM3 (1u << 1)", "RCC_APB1ENR_TIM3 (1u << 2)", F0,
     "RCC_APB1ENR_TIM3"),
    # an interrupt number
    ("stm32f1/stm32f1_regs.h", "DMA1_CH1_IRQ 11u", "DMA1_CH1_IRQ 12u", F1, "DMA1_CH1_IRQ"),
    ("stm32f1/stm32f1_regs.h", "USART2_BASE 0x40004400u", "USART2_BASE 0x40004800u", F1, "USART2_BASE"),
    # a multi-bit value past its field
    ("stm32f1/stm32f1_regs.h", "RCC_CFGR_ADCPRE_DIV6 (2u << 14)", "RCC_CFGR_ADCPRE_DIV6 (2u << 15)", F1,
     "RCC_CFGR_ADCPRE_DIV6"),
    # a composite with one field wrong
    ("stm32_common/stm32_core_regs.h", "(1u << 7) | (1u << 5) | (1u << 8)", "(1u << 6) | (1u << 5) | (1u << 8)",
     F1, "DMA_CCR_ADC_CIRCULAR"),
    # the PLL factor's meaning (x9 is 0111)
    ("stm32f1/stm32f1_regs.h", "RCC_CFGR_PLLMUL9 (7u << 18)", "RCC_CFGR_PLLMUL9 (9u << 18)", F1,
     "RCC_CFGR_PLLMUL9"),
    # a peripheral base
    ("stm32f0/stm32f0_regs.h", "GPIOA_BASE 0x48000000u", "GPIOA_BASE 0x48000400u", F0, "GPIOA_BASE"),
    # a new definition nobody checks
    ("stm32f1/stm32f1_regs.h", "#define UID_ADDR", "#define MYSTERY_VALUE 3u\n#define UID_ADDR", F1,
     "MYSTERY_VALUE"),
])
def test_a_wrong_definition_is_found(tmp_path, rel, old, new, part, name):
    errors = check_regs_svd.check_part(part, ports_with(tmp_path, rel, old, new))
    assert any(e.startswith(f"{part}: {name}:") for e in errors), errors


@needs_g0_svd
def test_the_g0_header_matches_the_svd():
    assert check_regs_svd.check_part(G0, ROOT / "hal/ports", G0_SVD) == []


@needs_g0_svd
@pytest.mark.parametrize("old, new, name", [
    ("RCC_CSR_RMVF (1u << 23)", "RCC_CSR_RMVF (1u << 24)", "RCC_CSR_RMVF"),  # the F0/F1's bit
    ("G0_FLASH_CR_PNB_SHIFT 3u", "G0_FLASH_CR_PNB_SHIFT 4u", "G0_FLASH_CR_PNB_SHIFT"),
    ("G0_FLASH_BASE_REG + 0x18u)", "G0_FLASH_BASE_REG + 0x1Cu)", "G0_FLASH_ECCR"),
    ("G0_USART2_IRQ 28u", "G0_USART2_IRQ 29u", "G0_USART2_IRQ"),
    ("G0_DMAMUX_BASE 0x40020800u", "G0_DMAMUX_BASE 0x40020900u", "G0_DMAMUX_BASE"),
    ("(8u << 8) | (1u << 28)", "(9u << 8) | (1u << 28)", "G0_RCC_PLLCFGR_64MHZ_FROM_HSI16"),
    ("G0_FLASH_SR_RDERR (1u << 14)", "G0_FLASH_SR_RDERR (1u << 13)", "G0_FLASH_SR_RDERR"),
])
def test_a_wrong_g0_definition_is_found(tmp_path, old, new, name):
    errors = check_regs_svd.check_part(G0, ports_with(tmp_path, "stm32g0/stm32g0_regs.h", old, new), G0_SVD)
    assert any(e.startswith(f"{G0}: {name}:") for e in errors), errors
