#ifndef DMA_TX_H
#define DMA_TX_H

#include <stdint.h>

#include "ports/stm32_common/stm32_core_regs.h"

/* MINC | DIR (memory to peripheral) | EN; bytes both sides; priority high
 * (PL = 2), below the receiving channel's very high. No interrupt: the
 * USART's TC says when the last byte has left. */
#define DMA_CCR_TX ((1u << 7) | (1u << 4) | (1u << 0) | (2u << 12))

/* Answers out of memory into a USART's data register, a byte each time the
 * USART asks (RM0008 13.3, RM0360 10.3): the CPU is not woken per byte.
 * The channel is off between transmissions (its counter and address take
 * writes only then), so starting one is three stores on the answer's path. */
static inline void dma_tx_init(uintptr_t channel, uintptr_t data_register)
{
    DMA_CCR(channel) = 0;
    DMA_CPAR(channel) = (uint32_t)data_register;
}

static inline void dma_tx_start(uintptr_t channel, const uint8_t *data, uint16_t len)
{
    DMA_CMAR(channel) = (uint32_t)(uintptr_t)data;
    DMA_CNDTR(channel) = len;
    DMA_CCR(channel) = DMA_CCR_TX;
}

/* Once the last byte has left (from the USART's TC interrupt). */
static inline void dma_tx_stop(uintptr_t channel)
{
    DMA_CCR(channel) = 0;
}

#endif
