/* The servo bus's instances on an STM32F030, from the board's declaration
 * (its board.h, included before this file): the F0 port drives USART1 with
 * its DMA requests on channels 2 (TX) and 3 (RX) (RM0360, "DMA request
 * mapping"; the F030K6 has no other USART), and a board that names other
 * instances is refused here, not built to drive USART1 silently. */
#ifndef STM32F0_BUS_H
#define STM32F0_BUS_H

#include "ports/stm32f0/stm32f0_regs.h"

#if !defined(BOARD_BUS_USART) || !defined(BOARD_BUS_DMA_TX) || !defined(BOARD_BUS_DMA_RX)
#error "board.h declares the bus: BOARD_BUS_USART, BOARD_BUS_DMA_TX and BOARD_BUS_DMA_RX (docs/building.md)"
#endif

_Static_assert(BOARD_BUS_USART == 1 && BOARD_BUS_DMA_TX == 2 && BOARD_BUS_DMA_RX == 3,
               "board.h: the STM32F0 port drives the bus on USART1 with DMA1 channels 2 (TX) and 3 "
               "(RX) only (RM0360)");

#define BUS_USART_BASE USART1_BASE

#endif
