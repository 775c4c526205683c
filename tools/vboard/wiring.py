"""Which of its part's instances and pins a virtual board's firmware uses,
from the board's declaration (board.h, through servo_image.board_facts):
the bus USART, its DMA channels and its clock, its TX pin; the bridge
timer and its CH1/CH2 pins; the ADC channels of the scan's four inputs.

An STM32F1 board declares them all (hal/ports/stm32f1/stm32f1_pins.h: a
pin is 0xPN, port P from 0 for A, pin N), and the virtual F103 wires
whichever it names: USART1, 2 or 3 on their DMA1 channels (RM0008 Table
78), TIM2, 3 or 4, any ADC1 inputs. The F0 and G0 ports drive USART1 on
PA9 and TIM3 on PA6/PA7 with ADC channels 0-3, which is what their
boards get; a board.h that declares another bus for them is refused."""
from dataclasses import dataclass

INPUTS = ("supply", "current", "ntc", "encoder")  # the scan's order (board_common.h)
ADC_FACTS = ("BOARD_ADC_SUPPLY", "BOARD_ADC_CURRENT", "BOARD_ADC_NTC", "BOARD_ADC_POSITION")
REFERENCE = {"BOARD_BUS_TX_PIN": 0x09, "BOARD_BRIDGE_TIMER": 3, "BOARD_BRIDGE_IN1_PIN": 0x06,
             "BOARD_BRIDGE_IN2_PIN": 0x07, **{fact: n for n, fact in enumerate(ADC_FACTS)}}
# RM0008 Table 78: each USART's DMA1 channels (TX, RX).
F1_USART_DMA = {1: (4, 5), 2: (7, 6), 3: (2, 3)}


@dataclass(frozen=True)
class Wiring:
    usart: int           # the bus USART's number
    dma_tx: int          # its DMA channels (the G0's: the ones its DMAMUX routes)
    dma_rx: int
    tx_pin: int          # 0xPN
    timer: int           # the bridge's timer
    bridge_pins: tuple   # (IN1, IN2): its CH1 and CH2, 0xPN
    adc: dict            # ADC channel -> what it reads (INPUTS)

    @property
    def usart_name(self) -> str:
        return f"USART{self.usart}"

    @property
    def timer_name(self) -> str:
        return f"TIM{self.timer}"

    def ports(self) -> list:
        """The GPIO ports (0 A, 1 B...) whose pins it uses, A always."""
        return sorted({0, self.tx_pin >> 4, *(p >> 4 for p in self.bridge_pins)})


def pin_name(pin: int) -> str:
    return f"P{'ABCD'[pin >> 4]}{pin & 0xF}"


def of(board: str, h: dict, part) -> Wiring:
    """The board's wiring on its part (parts.Part); ValueError, saying
    what the virtual part wires instead, where it cannot."""
    facts = {k: h.get(k, v) for k, v in REFERENCE.items()}
    usart, tx, rx = h.get("BOARD_BUS_USART"), h.get("BOARD_BUS_DMA_TX"), h.get("BOARD_BUS_DMA_RX")
    if part.family == "f1":
        if F1_USART_DMA.get(usart) != (tx, rx):
            raise ValueError(f"{board}: its board.h declares the bus on USART{usart} with DMA channels {tx} (TX) "
                             f"and {rx} (RX); the virtual {part.svd} wires USART1-3 on their own "
                             "(RM0008 Table 78: 4 and 5, 7 and 6, 2 and 3)")
    elif ((usart, tx, rx) != (1, part.usart_tx_dma, part.usart_rx_dma)
          or any(facts[k] != v for k, v in REFERENCE.items())):
        raise ValueError(f"{board}: its board.h declares the bus on USART{usart} with DMA channels {tx} (TX) "
                         f"and {rx} (RX); the virtual {part.svd} wires it on USART1 (PA9) with "
                         f"{part.usart_tx_dma} and {part.usart_rx_dma} only, the bridge on TIM3")
    return Wiring(usart, tx, rx, facts["BOARD_BUS_TX_PIN"], facts["BOARD_BRIDGE_TIMER"],
                  (facts["BOARD_BRIDGE_IN1_PIN"], facts["BOARD_BRIDGE_IN2_PIN"]),
                  {facts[fact]: what for fact, what in zip(ADC_FACTS, INPUTS)})
