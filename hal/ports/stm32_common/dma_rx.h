/* USART receive by DMA into the HAL's ring (RM0008 13 and RM0360 10, "DMA controller": the same channel on F1 and F0):
 * one channel in circular mode writes every received byte into
 * hal_rx_ring.data, with no code per byte; its counter (CNDTR, counting
 * down from the ring's size) is the write position, and a transfer-complete
 * interrupt, once a lap of the ring, counts laps. So `written` runs free
 * like a receive interrupt's would, and a main loop lapped by the DMA (held
 * up longer than a ring's time) sees how much it lost. No code runs per
 * byte or per frame: the line counts as heard when the main loop finds new
 * bytes, at most one pass late, which only makes the servo wait longer
 * for a quiet line.
 *
 * The channel's registers are found from `channel` (the address of its
 * CCR), so the benchmark can run this on registers in RAM. */
#ifndef STM32_DMA_RX_H
#define STM32_DMA_RX_H

#include <stdint.h>

#include "hal/hal_rx_ring.h"

struct dma_rx {
    uintptr_t channel;       /* address of the channel's CCR */
    struct hal_rx_ring *ring;
    volatile uint32_t lap_end; /* bytes written when the lap under way ends */
    uint32_t written;          /* bytes written as last seen */
};

/* Starts the channel on the peripheral's data register. */
void dma_rx_start(struct dma_rx *d, uintptr_t channel, uintptr_t data_register,
                  struct hal_rx_ring *ring);
/* From the channel's interrupt, after its transfer-complete flag is clear. */
void dma_rx_lap(struct dma_rx *d);
/* Brings ring->written up to date; bytes new since the last call mark the
 * line busy at now_us. Main loop. Shaped as hal_port.bus.rx_sync (dma: the
 * struct dma_rx). */
void dma_rx_sync(void *dma, uint32_t now_us);

#endif
