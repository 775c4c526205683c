/* The reference board: STM32F103 servo controller (pin map: README.md).
 * What differs from the other STM32 boards; the start-up path and the main
 * loop are the boards' shared one (boards/common/app_start.h). */
#include "board.h"
#include "board_io.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32f1/stm32f1_bus.h"
#include "ports/stm32f1/stm32f1_uart.h"
#include "ports/stm32f1/usart_hd.h"

#define BOARD_USART struct usart_hd
#define BOARD_BUS PORT_UART_BUS_ALL_DMA
#define BOARD_CORE_HZ F103_CORE_HZ
#define board_clock_init clock_f103_init

static void board_pins_init(void)
{
    bus_pins_init();
    /* PA0-PA3 analogue; PA6, PA7 TIM3 CH1/CH2 push-pull. */
    GPIOA_CRL = (GPIO_ANALOG << 0) | (GPIO_ANALOG << 4) | (GPIO_ANALOG << 8) |
                (GPIO_ANALOG << 12) | (GPIO_AF_PUSH_PULL_50MHZ << 24) |
                (GPIO_AF_PUSH_PULL_50MHZ << 28) | (0x4u << 16) | (0x4u << 20);
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
