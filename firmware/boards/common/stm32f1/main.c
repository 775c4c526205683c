/* An STM32F1 servo board (the reference board's pin map: its README.md),
 * its pins and instances from its board.h. What differs from the other
 * STM32 boards; the start-up path and the main
 * loop are the boards' shared one (boards/common/app_start.h). */
#include "board.h"
#include "boards/common/stm32f1/board_io.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32f1/stm32f1_bus.h"
#include "ports/stm32f1/stm32f1_pins.h"
#include "ports/stm32f1/stm32f1_uart.h"
#include "ports/stm32f1/usart_hd.h"

#define BOARD_USART struct usart_hd
#define BOARD_BUS PORT_UART_BUS_ALL_DMA
#define BOARD_CORE_HZ F103_CORE_HZ
#define board_clock_init clock_f103_init

static void board_pins_init(void)
{
    bus_pins_init();
    /* The ADC's inputs analogue, the bridge timer's CH1/CH2 push-pull:
     * the pins board.h names. */
    FRONT_END_PINS_INIT();
}

STM32F1_BUS_DEFINED

/* Sends by DMA; its transmission's end is the USART interrupt's. */
#define board_uart_start(usart, ring, dma)                              \
    do {                                                                \
        port_uart_init((usart), (ring), (dma), BUS_USART_PCLK_HZ(F103_PCLK1_HZ, F103_PCLK2_HZ), &bus_hw); \
        port_uart_send_by_dma(usart);                                   \
    } while (0)
#define board_interrupts_on() (NVIC_ISER(BUS_USART_IRQ / 32u) = 1u << (BUS_USART_IRQ % 32u))

#include "boards/common/app_start.h"
