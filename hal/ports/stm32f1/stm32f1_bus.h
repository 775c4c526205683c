/* The servo bus's instances on an STM32F1, from the board's declaration
 * (its board.h, included before this file): BOARD_BUS_USART (1, 2 or 3)
 * and the DMA1 channels of its requests, BOARD_BUS_DMA_TX and
 * BOARD_BUS_DMA_RX, checked against RM0008 when the board is built. It
 * names the port's instance (STM32F1_BUS), the handlers the vector table
 * calls for it, and the USART the bootloader stops before the jump. */
#ifndef STM32F1_BUS_H
#define STM32F1_BUS_H

#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32f1/stm32f1_uart.h"

#if !defined(BOARD_BUS_USART) || !defined(BOARD_BUS_DMA_TX) || !defined(BOARD_BUS_DMA_RX)
#error "board.h declares the bus: BOARD_BUS_USART, BOARD_BUS_DMA_TX and BOARD_BUS_DMA_RX (docs/building.md)"
#endif

_Static_assert(BOARD_BUS_USART >= 1 && BOARD_BUS_USART <= 3,
               "board.h: BOARD_BUS_USART is 1, 2 or 3 on an STM32F1 (RM0008)");
/* RM0008 Table 78, DMA1's requests: USART1 TX 4 RX 5, USART2 TX 7 RX 6,
 * USART3 TX 2 RX 3. */
_Static_assert(BOARD_BUS_DMA_TX == (BOARD_BUS_USART == 1 ? 4 : BOARD_BUS_USART == 2 ? 7 : 2) &&
                   BOARD_BUS_DMA_RX == (BOARD_BUS_USART == 1 ? 5 : BOARD_BUS_USART == 2 ? 6 : 3),
               "board.h: BOARD_BUS_DMA_TX and BOARD_BUS_DMA_RX are not its USART's DMA1 channels "
               "(RM0008 Table 78: USART1 4 and 5, USART2 7 and 6, USART3 2 and 3)");

/* The instances' facts are stm32f1_regs.h's, checked against ST's SVD. */
#define BUS_USART_BASE (BOARD_BUS_USART == 1 ? USART1_BASE : BOARD_BUS_USART == 2 ? USART2_BASE : USART3_BASE)
#define BUS_USART_IRQ (BOARD_BUS_USART == 1 ? USART1_IRQ : BOARD_BUS_USART == 2 ? USART2_IRQ : USART3_IRQ)
#define BUS_DMA_RX_IRQ (DMA1_CH1_IRQ + BOARD_BUS_DMA_RX - 1u)
/* Its clock: USART1 on APB2, USART2 and 3 on APB1 (RM0008's clock tree):
 * the board gives both bus clocks, the bus takes its own. */
#define BUS_USART_PCLK_HZ(pclk1_hz, pclk2_hz) (BOARD_BUS_USART == 1 ? (pclk2_hz) : (pclk1_hz))
#define BUS_USART_CLOCK_ON()                                                                        \
    (BOARD_BUS_USART == 1 ? (void)(RCC_APB2ENR |= RCC_APB2ENR_USART1)                              \
                          : (void)(RCC_APB1ENR |= BOARD_BUS_USART == 2 ? RCC_APB1ENR_USART2 : RCC_APB1ENR_USART3))
_Static_assert(DMA1_CH7_IRQ == DMA1_CH1_IRQ + 6u, "DMA1's channel interrupts are in a row (RM0008)");

#define STM32F1_BUS                                                                                \
    {.usart_base = BUS_USART_BASE, .dma_tx_ccr = DMA1_CCR_ADDR(BOARD_BUS_DMA_TX),                  \
     .dma_rx_ccr = DMA1_CCR_ADDR(BOARD_BUS_DMA_RX), .dma_rx_flags = DMA1_FLAGS(BOARD_BUS_DMA_RX),  \
     .dma_rx_irq = BUS_DMA_RX_IRQ}

/* The handlers by the names the vector table gives them
 * (startup_stm32f103.c), chosen by value: a board.h that writes 0x2 or 6u
 * gets the same names (pasting its text made USART0x2_IRQHandler, and the
 * weak default handled the bus). */
#if BOARD_BUS_USART == 1
#define BUS_USART_HANDLER USART1_IRQHandler
#elif BOARD_BUS_USART == 2
#define BUS_USART_HANDLER USART2_IRQHandler
#elif BOARD_BUS_USART == 3
#define BUS_USART_HANDLER USART3_IRQHandler
#else
#error "board.h: BOARD_BUS_USART is 1, 2 or 3 on an STM32F1 (RM0008)"
#endif
#if BOARD_BUS_DMA_RX == 3
#define BUS_DMA_RX_HANDLER DMA1_Channel3_IRQHandler
#elif BOARD_BUS_DMA_RX == 5
#define BUS_DMA_RX_HANDLER DMA1_Channel5_IRQHandler
#elif BOARD_BUS_DMA_RX == 6
#define BUS_DMA_RX_HANDLER DMA1_Channel6_IRQHandler
#else
#error "board.h: BOARD_BUS_DMA_RX is a USART's receive channel on an STM32F1: 5, 6 or 3 (RM0008 Table 78)"
#endif
/* The board's bus (bus_hw, for port_uart_init) and both handlers, in its
 * main.c or boot_main.c (one file an image). */
#define STM32F1_BUS_DEFINED                                 \
    static const struct stm32f1_bus bus_hw = STM32F1_BUS;   \
    void BUS_USART_HANDLER(void);     \
    void BUS_USART_HANDLER(void)      \
    {                                 \
        port_uart_irq();              \
    }                                 \
    void BUS_DMA_RX_HANDLER(void);    \
    void BUS_DMA_RX_HANDLER(void)     \
    {                                 \
        port_uart_dma_irq();          \
    }

#endif
