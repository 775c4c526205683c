/* The bus and the clock of a hal_port on an STM32F0: the servo's bus on
 * USART1 (usart_v2_hd.h) received by DMA1 channel 3, its clock from
 * SysTick. The board's main.c names these operations in its hal_port (ctx:
 * the usart_v2_hd; rx_sync: dma_rx_sync on the dma). */
#ifndef STM32F0_PORT_UART_H
#define STM32F0_PORT_UART_H

#include "ports/stm32_common/dma_rx.h"
#include "ports/stm32_common/systick_clock.h"
#include "hal/hal_port.h"
#include "ports/stm32f0/usart_v2_hd.h"

enum port_uart_send {
    PORT_UART_SEND_DMA, /* usart_v2_hd_send: by DMA1 channel 2, the USART's interrupt at the end */
    /* usart_v2_hd_send_polled: whole, from the main loop, for the bootloader,
     * whose vector table has no USART entry */
    PORT_UART_SEND_POLLED,
};

/* Starts USART1 for the bus (single wire, 115200 until data ID 36 says
 * otherwise) receiving into ring by dma; enables the DMA's interrupt, and
 * the USART's when it sends by DMA. */
void port_uart_init(struct usart_v2_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                    uint32_t pclk_hz, enum port_uart_send send);

/* A hal_port's bus on this port (rx_ctx: the dma_rx), sending by DMA or,
 * for the bootloader, whole from the main loop. */
#define PORT_UART_BUS                                                                 \
    {.now_us = systick_bus_now_us, .send = usart_v2_hd_send, .tx_done = usart_v2_hd_tx_done, \
     .set_baud = usart_v2_hd_set_baud, .rx_sync = dma_rx_sync}
#define PORT_UART_BUS_POLLED                                                                 \
    {.now_us = systick_bus_now_us, .send = usart_v2_hd_send_polled,                        \
     .tx_done = usart_v2_hd_tx_done, .set_baud = usart_v2_hd_set_baud, .rx_sync = dma_rx_sync}

#endif
