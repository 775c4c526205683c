"""The silicon a virtual board is built on: its core, its register
descriptions, its clock tree's reset clock, the DMA channels its USART
uses (the F0's and G0's; an F1 board's are its board.h's, wiring.py),
where its unique ID sits, its flash timings and the preset that builds its
images, and where a board's images are. The part's memory facts (flash,
RAM, page size, LSI) are hal/ports/parts.toml's, read through
servo_image.board_facts."""
from dataclasses import dataclass
from pathlib import Path

from servo_image import board_facts
from unicorn import arm_const as arm

REPO = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class Part:
    svd: str
    cpu: int
    has_vtor: bool
    irq_words: int
    cpi: float          # cycles an instruction: the target benchmark's model for this firmware
    names: dict         # role -> the SVD's peripheral name
    usart_rx_dma: int   # DMA channel of USART1_RX (RM0008 table 78, RM0360 table 26; the G0's board.h, by DMAMUX)
    usart_tx_dma: int   # ... and of USART1_TX
    dma_irqs: dict      # channel -> the SVD's interrupt name
    uid: int            # 96-bit unique ID (RM0008 30.2, RM0360 29.1, RM0444 40.1)
    program_s: float    # tPROG, the datasheet's longest
    erase_s: float      # tERASE, the datasheet's longest
    build: str          # the CMake preset that builds its images
    family: str = "f1"  # "f1", "f0" or "g0": which models its peripherals take
    system_memory: tuple = (0x1FFFF000, 0x1000)  # (base, size) mapped for the unique ID
    reset_hz: int = 8_000_000  # the clock from reset: HSI 8 MHz (F0, F1), HSI16 (G0)


PARTS = {
    # DS5319 (STM32F103x8/xB) "Flash memory characteristics": tPROG 40-70 us, tERASE 20-40 ms.
    # CPI 2.0: docs/benchmark.md (72 MHz, 2 wait states; the whole tick 1506 cycles / 762).
    "stm32f103": Part("STM32F103xx", arm.UC_CPU_ARM_CORTEX_M3, True, 2, 2.0,
                      {"rcc": "RCC", "flash": "FLASH", "dma": "DMA1", "usart": "USART1", "adc": "ADC1",
                       "tim": "TIM3", "iwdg": "IWDG", "gpio": "GPIOA"},
                      5, 4, {1: "DMA1_Channel1", 5: "DMA1_Channel5"}, 0x1FFFF7E8, 70e-6, 40e-3, "arm"),
    # DS9773 (STM32F030x4/6/8/C) "Flash memory characteristics": tPROG 53.5 us max, tERASE 40 ms max.
    # CPI 1.9: docs/benchmark.md (48 MHz, 1 wait state; the whole tick 4004 cycles / 2091).
    "stm32f030k6": Part("STM32F030", arm.UC_CPU_ARM_CORTEX_M0, False, 1, 1.9,
                        {"rcc": "RCC", "flash": "Flash", "dma": "DMA", "usart": "USART1", "adc": "ADC",
                         "tim": "TIM3", "iwdg": "IWDG", "gpio": "GPIOA", "syscfg": "SYSCFG"},
                        3, 2, {1: "DMA_CH1", 3: "DMA_CH2_3"}, 0x1FFFF7AC, 53.5e-6, 40e-3, "arm-m0",
                        family="f0"),
    # The Cortex-M0+ (ARMv6-M, with a VTOR: ARMv6-M B3.2.5) on Unicorn's M0,
    # which runs the same instruction set. DS12992 (STM32G031x4/x6/x8) "Flash
    # memory characteristics": tPROG (a double word) 125 us max, tERASE (a page)
    # 40 ms max. CPI 1.86: docs/benchmark.md's M0+ model (64 MHz, 2 wait
    # states, its cache not modelled: the whole tick 1497 cycles / 806.1).
    # System memory and the unique ID: RM0444 2.2 (0x1FFF0000, the ID at 0x1FFF7590).
    "stm32g031k8": Part("STM32G031", arm.UC_CPU_ARM_CORTEX_M0, True, 1, 1.86,
                        {"rcc": "RCC", "flash": "FLASH", "dma": "DMA1", "usart": "USART1", "adc": "ADC",
                         "tim": "TIM3", "iwdg": "IWDG", "gpio": "GPIOA", "dmamux": "DMAMUX"},
                        3, 2, {1: "DMA1_Channel1", 2: "DMA1_Channel2_3", 3: "DMA1_Channel2_3"},
                        0x1FFF7590, 125e-6, 40e-3, "arm-g0", family="g0",
                        system_memory=(0x1FFF0000, 0x8000), reset_hz=16_000_000),
}

# The parts of hal/ports/parts.toml a virtual board emulates, and the
# shipped board whose PARTS entry models it (the F103CB: the C8 with more
# flash, which parts.toml gives).
EMULATED = {"stm32f103c8": "stm32f103", "stm32f103cb": "stm32f103", "stm32f030k6": "stm32f030k6",
            "stm32g031k8": "stm32g031k8"}


def part_of(board) -> Part:
    """The silicon of a shipped board (by name) or of a board folder (a
    Path), by the part its board.cmake names."""
    if not isinstance(board, Path) and board in PARTS:
        return PARTS[board]
    name = board_facts.part_name(board)
    if name not in EMULATED:
        raise ValueError(f"{board}: its part {name or '(none)'} has no virtual board "
                         f"(the emulated parts: {', '.join(sorted(EMULATED))})")
    return PARTS[EMULATED[name]]


def name_of(board) -> str:
    """A board's name: a shipped board's, or its folder's (a Path)."""
    return board.name if isinstance(board, Path) else board


def _built(board, build) -> Path:
    """The board's folder in its build: the build tree given, else the
    checkout's build of its part's preset."""
    tree = Path(build) if build else REPO / "build" / part_of(board).build
    return tree / "firmware/boards" / name_of(board)


def images(board, build=None) -> tuple:
    """(bootloader .bin, application update image .img, application .bin)
    of the board's build."""
    folder, name = _built(board, build), name_of(board)
    return folder / f"servo_{name}_boot.bin", folder / f"servo_{name}.img", folder / f"servo_{name}.bin"


def elf(board, build=None) -> Path:
    """The application's ELF, which names the main loop's pass (idle_skip.py)."""
    return _built(board, build) / f"servo_{name_of(board)}.elf"


