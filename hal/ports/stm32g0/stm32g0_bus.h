/* The servo bus's instances on an STM32G031, from the board's declaration
 * (its board.h, included before this file): USART1 or USART2, on any two
 * of DMA1's channels 2 and 3 (they share one interrupt, which counts the
 * receive ring's laps), each given its request through the DMAMUX
 * (RM0444 11; the request numbers, stm32g0_regs.h). A board names the
 * USART, the channels and the requests; a request that is not its USART's
 * is refused here. */
#ifndef STM32G0_BUS_H
#define STM32G0_BUS_H

#include "ports/stm32g0/stm32g0_regs.h"

#if !defined(BOARD_BUS_USART) || !defined(BOARD_BUS_DMA_TX) || !defined(BOARD_BUS_DMA_RX) || \
    !defined(BOARD_BUS_DMAMUX_TX) || !defined(BOARD_BUS_DMAMUX_RX)
#error "board.h declares the bus: BOARD_BUS_USART, BOARD_BUS_DMA_TX/_RX and BOARD_BUS_DMAMUX_TX/_RX (docs/building.md)"
#endif

#if BOARD_BUS_USART == 1
#define BUS_USART_BASE G0_USART1_BASE
#define BUS_USART_IRQ G0_USART1_IRQ
_Static_assert(BOARD_BUS_DMAMUX_RX == G0_DMAMUX_REQ_USART1_RX && BOARD_BUS_DMAMUX_TX == G0_DMAMUX_REQ_USART1_TX,
               "board.h: USART1's DMAMUX requests are 50 (RX) and 51 (TX) (RM0444 11.3.2)");
#elif BOARD_BUS_USART == 2
#define BUS_USART_BASE G0_USART2_BASE
#define BUS_USART_IRQ G0_USART2_IRQ
_Static_assert(BOARD_BUS_DMAMUX_RX == G0_DMAMUX_REQ_USART2_RX && BOARD_BUS_DMAMUX_TX == G0_DMAMUX_REQ_USART2_TX,
               "board.h: USART2's DMAMUX requests are 52 (RX) and 53 (TX) (RM0444 11.3.2)");
#else
#error "board.h: the G0 port drives the bus on USART1 or USART2"
#endif

_Static_assert((BOARD_BUS_DMA_TX == 2 && BOARD_BUS_DMA_RX == 3) || (BOARD_BUS_DMA_TX == 3 && BOARD_BUS_DMA_RX == 2),
               "board.h: the G0 port's bus takes DMA1 channels 2 and 3 (one interrupt, DMA1_Channel2_3)");

/* The port's description of the bus (stm32g0_uart.h), from the board's. */
#define G0_BUS_FROM_BOARD                                                                   \
    {.usart = BUS_USART_BASE, .irq = BUS_USART_IRQ, .dma_tx = BOARD_BUS_DMA_TX,             \
     .dma_rx = BOARD_BUS_DMA_RX, .req_tx = BOARD_BUS_DMAMUX_TX, .req_rx = BOARD_BUS_DMAMUX_RX}

#endif
