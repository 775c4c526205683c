/* The bus and the clock of a hal_port on an STM32G0: the servo's bus on
 * USART1 or USART2 (the F0's half-duplex driver, ../stm32f0/usart_v2_hd.h:
 * the G0's USART has its registers and bits), received by a DMA1 channel
 * whose request the DMAMUX routes, its clock from SysTick. The board's
 * main.c names these operations in its hal_port. */
#ifndef STM32G0_UART_H
#define STM32G0_UART_H

#include "ports/stm32_common/dma_rx.h"
#include "ports/stm32_common/systick_clock.h"
#include "hal/hal_port.h"
#include "ports/stm32f0/usart_v2_hd.h"

/* Which USART, its interrupt, its two DMA1 channels and their DMAMUX
 * requests (stm32g0_bus.h's G0_BUS_FROM_BOARD). */
struct g0_bus {
    uintptr_t usart;
    uint8_t irq;
    uint8_t dma_tx, dma_rx;
    uint8_t req_tx, req_rx;
};

enum g0_uart_send {
    G0_UART_SEND_DMA,    /* usart_v2_hd_send: by DMA, the USART's interrupt at the end */
    G0_UART_SEND_POLLED, /* usart_v2_hd_send_polled: whole, from the bootloader's loop */
};

/* Starts the bus's USART (single wire, 115200 until data ID 36 says
 * otherwise) receiving into ring by dma; enables the DMA channels'
 * interrupt, and the USART's when it sends by DMA. */
void g0_uart_init(struct usart_v2_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                  const struct g0_bus *bus, uint32_t pclk_hz, enum g0_uart_send send);

#define G0_UART_BUS                                                                          \
    {.now_us = systick_bus_now_us, .send = usart_v2_hd_send, .tx_done = usart_v2_hd_tx_done, \
     .set_baud = usart_v2_hd_set_baud, .rx_sync = dma_rx_sync}
#define G0_UART_BUS_POLLED                                                                   \
    {.now_us = systick_bus_now_us, .send = usart_v2_hd_send_polled,                          \
     .tx_done = usart_v2_hd_tx_done, .set_baud = usart_v2_hd_set_baud, .rx_sync = dma_rx_sync}

#endif
