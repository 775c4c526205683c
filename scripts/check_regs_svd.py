#!/usr/bin/env python3
"""Checks the ports' register definitions against ST's register descriptions.

    python3 scripts/check_regs_svd.py [--header-dir DIR] [--svd-dir DIR]

Every macro that hal/ports/stm32f1/stm32f1_regs.h, stm32f0/stm32f0_regs.h
and stm32_common/stm32_core_regs.h define is evaluated by the host C compiler
(with the part's header, so the shared header is checked against both parts)
and judged against the part's SVD file as cmsis-svd 0.4 bundles it
(STMicro/STM32F103xx.svd, STMicro/STM32F030.svd), and stm32g0/stm32g0_regs.h
against ST's STM32G031.svd where it is given (--svd-dir; no package ships it):

- a register (REG32, *_ADDR, *_OFFSET from its peripheral's *_BASE) must be
  the register of that name at that address;
- a peripheral base must be that peripheral's base address;
- a bit or field value (NAME = REGISTER_FIELD[_VALUE]) must set only the
  bits of that field, and a one-bit field exactly its bit;
- a value that sets several fields is listed in COMPOSITES with the field
  values it means, and must equal them placed where the SVD puts them;
- an interrupt number must be the SVD's number for the interrupt named in
  IRQS; a *_SHIFT, where its field starts.

A macro that fits none of these is named in NOT_IN_SVD with where its value
comes from instead, or the check fails: a new definition is checked too.
Exit 1 with one line per mismatch."""
import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PORTS = ROOT / "hal/ports"
PARTS = {
    "STM32F103xx": "stm32f1/stm32f1_regs.h",
    "STM32F030": "stm32f0/stm32f0_regs.h",
    "STM32G031": "stm32g0/stm32g0_regs.h",
}
# What a part's header is compiled with.
DEFINES = {"STM32G031": ["-DSTM32_FAMILY_G0"]}
# SVD files no package on PyPI ships (cmsis-svd 0.4's stop before the G0;
# 0.5 and 0.6 ship none, pyOCD's have no G0): NAME.svd in the folder given
# (--svd-dir, or $SERVO_SVD_DIR), or the part is not checked, and said so.
SVD_GIVEN = {"STM32G031"}


def svd_file(svd_name: str, svd_dir=None):
    """The part's SVD file where it is not packaged: a Path, or None."""
    folder = svd_dir or os.environ.get("SERVO_SVD_DIR")
    path = Path(folder) / f"{svd_name}.svd" if folder else None
    return path if path and path.is_file() else None
CORE = "stm32_common/stm32_core_regs.h"

# Arguments for the function-like macros: the instance each port uses.
CALLS = {
    "USART_": "USART1_BASE", "TIM_": "TIM3_BASE", "NVIC_": "0u",
    "DMA_": "DMA1_CCR_ADDR(1u)", "DMA1_CCR_ADDR": "1u", "DMA1_FLAGS": "1u",
}

# A part's own instances where its header names them otherwise.
PART_CALLS = {"STM32G031": {"USART_": "G0_USART1_BASE", "G0_DMAMUX_CCR": "1u"}}

# Where a field's name in the SVD is not the macro's.
FIELD_NAMES = {
    ("STM32F103xx", "RCC_APB2ENR_AFIO"): "AFIOEN",
    ("STM32F103xx", "RCC_APB2ENR_GPIOA"): "IOPAEN",
    ("STM32F103xx", "RCC_AHBENR_DMA1"): "DMA1EN",
    ("STM32F103xx", "RCC_APB2ENR_ADC1"): "ADC1EN",
    ("STM32F103xx", "RCC_APB1ENR_USART2"): "USART2EN",
    ("STM32F103xx", "RCC_APB1ENR_USART3"): "USART3EN",
    ("STM32F030", "RCC_AHBENR_GPIOA"): "IOPAEN",
    ("STM32F030", "RCC_AHBENR_DMA1"): "DMAEN",
    ("STM32F030", "RCC_APB2ENR_ADC1"): "ADCEN",
    ("STM32F030", "RCC_APB2ENR_SYSCFG"): "SYSCFGEN",
    ("STM32F030", "FLASH_SR_WRPRTERR"): "WRPRT",
    (None, "RCC_APB2ENR_USART1"): "USART1EN",
    (None, "RCC_APB1ENR_TIM3"): "TIM3EN",
    ("STM32F030", "RCC_CFGR_PPRE1_DIV2"): None,  # F1 only (F0's is PPRE)
    ("STM32G031", "RCC_CSR_PORRSTF"): "PWRRSTF",
    (None, "G0_RCC_IOPENR_GPIOA"): "IOPAEN",
    (None, "G0_RCC_AHBENR_DMA1"): "DMAEN",
    (None, "G0_RCC_APBENR1_TIM3"): "TIM3EN",
    (None, "G0_RCC_APBENR1_USART2"): "USART2EN",
    (None, "G0_RCC_APBENR2_USART1"): "USART1EN",
    (None, "G0_RCC_APBENR2_ADC"): "ADCEN",
    (None, "G0_FLASH_SR_BSY1"): "BSY",
    (None, "G0_FLASH_ECCR_ADDR_MASK"): "ADDR_ECC",
}

# Where a register's name in the SVD is not the macro's last word.
REGISTER_NAMES = {"G0_RCC_PLLCFGR": "PLLSYSCFGR", "G0_DMAMUX_CCR": "C0CR"}

# Values that set several fields: {macro: (register macro, {field: value})}.
# Function-like ones are evaluated with CALLS' argument.
COMPOSITES = {
    "DMA_CCR_ADC_CIRCULAR": ("DMA_CCR", {"MINC": 1, "CIRC": 1, "PSIZE": 1, "MSIZE": 1, "EN": 1}),
    "DMA1_FLAGS": ("DMA1_ISR", {"GIF1": 1, "TCIF1": 1, "HTIF1": 1, "TEIF1": 1}),
    "TIM_CCMR1_PWM1_BOTH": ("TIM_CCMR1", {"OC1M": 6, "OC1PE": 1, "OC2M": 6, "OC2PE": 1}),
    "TIM_CCER_CC1E_CC2E": ("TIM_CCER", {"CC1E": 1, "CC2E": 1}),
    "USART_ICR_CLEAR": ("USART_ICR", {"PECF": 1, "FECF": 1, "NCF": 1, "ORECF": 1,
                                      "IDLECF": 1, "TCCF": 1}),
    # A 4-bit pin configuration of CRL/CRH: MODE in bits 0-1, CNF in 2-3
    # (checked on pin 0's pair).
    "GPIO_ANALOG": ("GPIOA_CRL", {"MODE0": 0, "CNF0": 0}),
    "GPIO_AF_PUSH_PULL_50MHZ": ("GPIOA_CRL", {"MODE0": 3, "CNF0": 2}),
    "GPIO_AF_OPEN_DRAIN_50MHZ": ("GPIOA_CRL", {"MODE0": 3, "CNF0": 3}),
    "GPIO_MODE_AF": ("GPIOA_MODER", {"MODER0": 2}),
    "GPIO_MODE_ANALOG": ("GPIOA_MODER", {"MODER0": 3}),
    # PLL multiplication factor: x N is N - 2 (RM0008 7.3.2, RM0360 6.4.2).
    "RCC_CFGR_PLLMUL9": ("RCC_CFGR", {"PLLMUL": 9 - 2}),
    "RCC_CFGR_PLLMUL6": ("RCC_CFGR", {"PLLMUL": 6 - 2}),
    "RCC_CFGR_PLLMUL12": ("RCC_CFGR", {"PLLMUL": 12 - 2}),
    "G0_GPIO_MODE_AF": ("G0_GPIOA_MODER", {"MODER0": 2}),
    "G0_GPIO_MODE_ANALOG": ("G0_GPIOA_MODER", {"MODER0": 3}),
    "G0_RCC_PLLCFGR_64MHZ_FROM_HSI16": ("G0_RCC_PLLCFGR", {"PLLSRC": 2, "PLLM": 0, "PLLN": 8,
                                                           "PLLREN": 1, "PLLR": 1}),
    "G0_FLASH_SR_ERRORS": ("G0_FLASH_SR", {f: 1 for f in ("OPERR", "PROGERR", "WRPERR", "PGAERR", "SIZERR",
                                                          "PGSERR", "MISERR", "FASTERR", "RDERR",
                                                          "OPTVERR")}),
}
# A part's own meaning of a shared one. ST's STM32G031 SVD numbers DMA
# ISR's flags by their bit (GIF0, TCIF1, HTIF2, TEIF3 for channel 1).
PART_COMPOSITES = {
    "STM32G031": {"DMA1_FLAGS": ("DMA1_ISR", {"GIF0": 1, "TCIF1": 1, "HTIF2": 1, "TEIF3": 1})},
}

# Interrupt numbers: {macro: {part: the SVD's interrupt name}}.
IRQS = {
    "USART1_IRQ": {"STM32F103xx": "USART1", "STM32F030": "USART1"},
    "USART2_IRQ": {"STM32F103xx": "USART2"},
    "USART3_IRQ": {"STM32F103xx": "USART3"},
    "DMA1_CH1_IRQ": {"STM32F103xx": "DMA1_Channel1"},
    "DMA1_CH7_IRQ": {"STM32F103xx": "DMA1_Channel7"},
    "DMA1_CH3_IRQ": {"STM32F030": "DMA_CH2_3"},
    "G0_USART1_IRQ": {"STM32G031": "USART1"},
    "G0_USART2_IRQ": {"STM32G031": "USART2"},
    "G0_DMA1_CH2_3_IRQ": {"STM32G031": "DMA_Channel2_3"},
}

# Not described by ST's SVD files: where the value comes from.
NOT_IN_SVD = {
    "REG32": "the access helper itself",
    "SYSTICK_CTRL": "ARM core (ARMv7-M ARM B3.3.2, ARMv6-M ARM B3.3.2)",
    "SYSTICK_LOAD": "ARM core (ARMv7-M ARM B3.3.2)",
    "SYSTICK_VAL": "ARM core (ARMv7-M ARM B3.3.2)",
    "SYSTICK_ENABLE_CORE_CLOCK_IRQ": "ARM core SYST_CSR (ARMv7-M ARM B3.3.3)",
    "SCB_ICSR": "ARM core (ARMv7-M ARM B3.2.2)",
    "SCB_ICSR_PENDSTSET": "ARM core ICSR (ARMv7-M ARM B3.2.4)",
    "SCB_AIRCR": "ARM core (ARMv7-M ARM B3.2.2)",
    "SCB_AIRCR_RESET": "ARM core AIRCR (ARMv7-M ARM B3.2.6)",
    # The fault registers and the MPU: the M3 only (ARMv6-M has none of them).
    "SCB_SHCSR": "ARM core (ARMv7-M ARM B3.2.2; PM0056 SHCSR)",
    "SCB_SHCSR_FAULTS_OWN": "ARM core SHCSR MEMFAULTENA/BUSFAULTENA/USGFAULTENA (PM0056)",
    "SCB_CFSR": "ARM core (ARMv7-M ARM B3.2.2; PM0056 CFSR)",
    "SCB_HFSR": "ARM core (ARMv7-M ARM B3.2.2; PM0056 HFSR)",
    "MPU_CTRL": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_CTRL)",
    "MPU_RNR": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_RNR)",
    "MPU_RBAR": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_RBAR)",
    "MPU_RASR": "ARM core PMSAv7 (ARMv7-M ARM B3.5; PM0056 MPU_RASR)",
    "MPU_CTRL_ON_DEFAULT_MAP": "ARM core MPU_CTRL ENABLE|PRIVDEFENA (PM0056)",
    "FLASH_KEY1": "RM0008 3.3.1 / RM0360 3.2.2 (key values)",
    "FLASH_KEY2": "RM0008 3.3.1 / RM0360 3.2.2 (key values)",
    "IWDG_KEY_START": "RM0008 19.4.1 / RM0360 18.4.1 (key values)",
    "IWDG_KEY_ACCESS": "RM0008 19.4.1 / RM0360 18.4.1 (key values)",
    "IWDG_KEY_RELOAD": "RM0008 19.4.1 / RM0360 18.4.1 (key values)",
    "UID_ADDR": "system memory: RM0008 30.2, RM0360 29.1",
    "G0_UID_ADDR": "system memory: RM0444 40.1",
    "G0_FLASH_KEY1": "RM0444 3.3.6 (key values)",
    "G0_FLASH_KEY2": "RM0444 3.3.6 (key values)",
    "IWDG_COUNTS_PER_MS": "the LSI's frequency (DS12992; parts.toml lsi_hz) over PR 0's 4",
    "G0_DMAMUX_REQ_ADC": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART1_RX": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART1_TX": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART2_RX": "DMAMUX request numbers: RM0444 11.3.2",
    "G0_DMAMUX_REQ_USART2_TX": "DMAMUX request numbers: RM0444 11.3.2",
}
# Not in one part's SVD only.
PART_NOT_IN_SVD = {
    "STM32G031": {n: "ARM core NVIC (ARMv6-M ARM B3.4): ST's STM32G031 SVD has no NVIC"
                  for n in ("NVIC_ISER", "NVIC_ICER", "NVIC_ICPR")},
}


def defined_macros(header: Path) -> list:
    """[(name, is_function_like)] in the order the header defines them."""
    out = []
    for line in header.read_text().splitlines():
        m = re.match(r"#define\s+([A-Z0-9_]+)(\()?", line)
        if m and not m.group(1).endswith("_H"):
            out.append((m.group(1), bool(m.group(2))))
    return out


def expression(name: str, function_like: bool, calls=CALLS) -> str:
    if not function_like:
        return name
    arg = next((a for prefix, a in calls.items() if name.startswith(prefix)), None)
    return f"{name}({arg})" if arg else ""


def evaluate(header_dir: Path, part_header: str, names: list, defines=(), calls=CALLS) -> dict:
    """{name: (value, is_register)}: REG32(a) becomes a marked a."""
    lines = [f'#include "ports/{part_header}"', "#include <stdio.h>", "#undef REG32",
             "#define REG32(a) (0x100000000ull | (unsigned long long)(a))", "int main(void) {"]
    for name, fn in names:
        expr = expression(name, fn, calls)
        if expr and name != "REG32":  # what this part's build leaves out, left out
            lines += [f"#ifdef {name}", f'printf("%s %llu\\n", "{name}", (unsigned long long)({expr}));',
                      "#endif"]
    lines.append("return 0; }")
    with tempfile.TemporaryDirectory() as tmp:
        src, exe = Path(tmp) / "eval.c", Path(tmp) / "eval"
        src.write_text("\n".join(lines) + "\n")
        dirs = [f"-I{header_dir.parent}"]  # the headers name each other as ports/...
        subprocess.run(["cc", "-w", *defines, *dirs, str(src), "-o", str(exe)], check=True)
        out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    values = {}
    for line in out.splitlines():
        name, value = line.split()
        v = int(value)
        values[name] = (v & 0xFFFFFFFF, bool(v >> 32))
    return values


class Part:
    def __init__(self, svd_name: str, svd_file=None):
        from cmsis_svd.parser import SVDParser
        self.name = svd_name
        parser = (SVDParser.for_xml_file(str(svd_file)) if svd_file
                  else SVDParser.for_packaged_svd("STMicro", svd_name + ".svd"))
        self.device = parser.get_device()
        self.by_address = {}
        self.bases = {}
        self.interrupts = {}
        for p in self.device.peripherals:
            self.bases[p.base_address] = p.name
            for r in p.registers:
                self.by_address.setdefault(p.base_address + r.address_offset, []).append((p.name, r))
            for i in p.interrupts or []:
                self.interrupts[i.name] = i.value


def plain(name: str) -> str:
    """The name without its family's prefix: G0_RCC_BASE -> RCC_BASE."""
    return re.sub(r"^G0_", "", name)


def register_token(name: str) -> str:
    """USART_SR -> SR, DMA1_CCR5_ADDR -> CCR5, USART_RDR_OFFSET -> RDR."""
    stem = re.sub(r"_(ADDR|OFFSET)$", "", name)
    return stem.split("_")[-1]


def register_matches(token: str, svd_name: str) -> bool:
    # The SVD numbers a register the header takes by argument (CCR1, ISER0)
    # and names a timer's CCMR by its mode (CCMR1_Output).
    return svd_name in (token, token + "0", token + "_Output") or re.fullmatch(token + r"\d", svd_name)


def check_part(svd_name: str, header_dir: Path, svd_file=None) -> list:
    part = Part(svd_name, svd_file)
    part_header = PARTS[svd_name]
    names = defined_macros(header_dir / CORE) + defined_macros(header_dir / part_header)
    values = evaluate(header_dir, part_header, names, DEFINES.get(svd_name, ()), {**CALLS, **PART_CALLS.get(svd_name, {})})
    errors = []
    registers = {}  # register macro -> (peripheral, svd register)
    not_in_svd = {**NOT_IN_SVD, **PART_NOT_IN_SVD.get(svd_name, {})}
    composites = {**COMPOSITES, **PART_COMPOSITES.get(svd_name, {})}

    def fail(name, why):
        errors.append(f"{svd_name}: {name}: {why}")

    # Registers first: the fields are looked up through them.
    for name, fn in names:
        if name not in values:
            continue
        value, is_reg = values[name]
        if name.endswith("_OFFSET"):
            base = next((values[b][0] for b, _ in names if b.endswith("_BASE") and plain(name).split("_")[0] in b), None)
            value, is_reg = (base or 0) + value, True
        if not (is_reg or name.endswith("_ADDR")) or name in not_in_svd:
            continue
        found = part.by_address.get(value, [])
        token = REGISTER_NAMES.get(name, register_token(name))
        match = [(p, r) for p, r in found if register_matches(token, r.name)]
        if not match:
            have = ", ".join(f"{p}.{r.name}" for p, r in found) or "no register"
            fail(name, f"{value:#010x} is {have} in the SVD, not {register_token(name)}")
            continue
        registers[name] = match[0]

    for name, fn in names:
        if name in not_in_svd or name in registers:
            continue
        if name not in values:
            if fn and name not in composites:
                fail(name, "a function-like macro with no argument in CALLS")
            continue
        value, is_reg = values[name]
        if is_reg or name.endswith(("_ADDR", "_OFFSET")):
            continue  # a register that failed above
        if name.endswith("_BASE") or plain(name) == "FLASH_BASE_REG":
            periph = part.bases.get(value)
            want = plain(name).replace("_BASE_REG", "").replace("_BASE", "")
            if periph is None or periph.upper().rstrip("1") != want.upper().rstrip("1"):
                fail(name, f"{value:#010x} is the base of {periph or 'nothing'} in the SVD, not {want}")
            continue
        if name in IRQS:
            irq = IRQS[name].get(svd_name)
            if irq is None:
                fail(name, "no interrupt named for this part in IRQS")
            elif part.interrupts.get(irq) != value:
                fail(name, f"{value} is not {irq}'s interrupt number ({part.interrupts.get(irq)})")
            continue
        if name in composites:
            reg_macro, fields = composites[name]
            if reg_macro not in registers:
                if reg_macro in values or any(n == reg_macro for n, _ in names):
                    fail(name, f"its register {reg_macro} is not in the SVD")
                continue  # a register the other part's header defines
            _, reg = registers[reg_macro]
            by_name = {f.name: f for f in reg.fields}
            want = 0
            for field, v in fields.items():
                f = by_name.get(field)
                if f is None:
                    fail(name, f"{reg.name} has no field {field} in the SVD")
                    break
                want |= v << f.bit_offset
            else:
                if want != value:
                    fail(name, f"{value:#x} is not {fields} in {reg.name} ({want:#x})")
            continue
        check_field(part, name, value, registers, names, fail)
    return errors


def check_field(part, name, value, registers, names, fail):
    """NAME = REGISTER_FIELD[_VALUE]: only the field's bits."""
    prefix = max((r for r in registers if name.startswith(r + "_")), key=len, default=None)
    if prefix is None:
        # A register only the other part defines keeps its fields out.
        if not any(name.startswith(n + "_") for n, _ in names):
            fail(name, "no register of this header starts its name: add it to COMPOSITES or NOT_IN_SVD")
        return
    _, reg = registers[prefix]
    rest = name[len(prefix) + 1:].split("_")
    key = (part.name, name) if (part.name, name) in FIELD_NAMES else (None, name)
    if key in FIELD_NAMES and FIELD_NAMES[key] is None:
        return
    if rest[-1] == "SHIFT":
        rest = rest[:-1]
    candidates = [FIELD_NAMES[key]] if key in FIELD_NAMES else ["_".join(rest[:i]) for i in range(len(rest), 0, -1)]
    field = next((f for c in candidates for f in reg.fields if f.name == c), None)
    if field is None:
        fail(name, f"{reg.name} has no field {candidates[-1]} in the SVD")
        return
    if name.endswith("_SHIFT"):  # where the field starts
        if value != field.bit_offset:
            fail(name, f"{value} is not where {reg.name}.{field.name} starts (bit {field.bit_offset})")
        return
    mask = ((1 << field.bit_width) - 1) << field.bit_offset
    if value & ~mask or value == 0 and field.bit_width == 1:
        fail(name, f"{value:#x} lies outside {reg.name}.{field.name} (bits {field.bit_offset}.."
                   f"{field.bit_offset + field.bit_width - 1})")
    elif field.bit_width == 1 and value != mask:
        fail(name, f"{value:#x} is not {reg.name}.{field.name} ({mask:#x})")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--header-dir", type=Path, default=PORTS, help="the ports' folder, named ports (its headers include each other as ports/...; tests use a copy)")
    ap.add_argument("--svd-dir", type=Path, help=f"a folder with {', '.join(sorted(SVD_GIVEN))}.svd (default $SERVO_SVD_DIR)")
    args = ap.parse_args()
    errors, checked = [], 0
    for svd_name, header in PARTS.items():
        given = svd_file(svd_name, args.svd_dir) if svd_name in SVD_GIVEN else None
        if svd_name in SVD_GIVEN and given is None:
            print(f"{svd_name}: not checked: no {svd_name}.svd (--svd-dir or $SERVO_SVD_DIR)")
            continue
        errors += check_part(svd_name, args.header_dir, given)
        checked += len(defined_macros(args.header_dir / CORE) + defined_macros(args.header_dir / header))
    for e in errors:
        print(e)
    print(f"registers: {checked} definitions against ST's SVD files, {len(errors)} mismatches")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
