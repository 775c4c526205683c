#include "ports/stm32_common/dma_rx.h"

#include "ports/stm32_common/stm32_core_regs.h"

/* MINC | CIRC | TCIE | EN; bytes both sides; priority very high (PL = 3). */
#define DMA_CCR_RX_CIRCULAR ((1u << 7) | (1u << 5) | (1u << 1) | (1u << 0) | (3u << 12))

void dma_rx_start(struct dma_rx *d, uintptr_t channel, uintptr_t data_register,
                  struct hal_rx_ring *ring)
{
    *d = (struct dma_rx){.channel = channel, .ring = ring, .lap_end = hal_rx_ring_size(ring)};
    DMA_CCR(channel) = 0;
    DMA_CPAR(channel) = (uint32_t)data_register;
    DMA_CMAR(channel) = (uint32_t)(uintptr_t)ring->data;
    DMA_CNDTR(channel) = hal_rx_ring_size(ring); /* up to 65535 (RM0008 13.4.4) */
    DMA_CCR(channel) = DMA_CCR_RX_CIRCULAR;
}

void dma_rx_lap(struct dma_rx *d)
{
    d->lap_end += hal_rx_ring_size(d->ring);
}

void dma_rx_sync(void *dma, uint32_t now_us)
{
    struct dma_rx *d = dma;
    /* Lap end, counter, lap end: a lap that ended in between waits for the next
     * call, as does a counter that has reloaded at the end of a lap a
     * moment before the interrupt counts it (a position behind the last
     * one seen). */
    uint32_t lap_end = d->lap_end;
    uint32_t left = DMA_CNDTR(d->channel);
    if (lap_end != d->lap_end) {
        return;
    }
    uint32_t written = lap_end - left;
    if ((int32_t)(written - d->written) > 0) {
        d->written = written;
        d->ring->written = written;
        d->ring->heard_us = now_us;
    }
}
