/* The bus and the clock of a hal_port on an STM32F1: the servo's bus on
 * the USART the board names (usart_hd.h), received by DMA or byte by byte,
 * its clock from SysTick. Shared by every F1 board; the board's main.c names
 * these operations in its hal_port (ctx: the usart_hd). */
#ifndef STM32F1_PORT_UART_H
#define STM32F1_PORT_UART_H

#include "ports/stm32_common/dma_rx.h"
#include "ports/stm32_common/systick_clock.h"
#include "hal/hal_port.h"
#include "ports/stm32f1/usart_hd.h"

/* The bus's instance: its USART, the DMA1 channels of its requests (their
 * CCR addresses), and the receive channel's flags and interrupt. A board
 * gives it from its board.h (STM32F1_BUS, stm32f1_bus.h). */
struct stm32f1_bus {
    uint32_t usart_base;
    uint32_t dma_tx_ccr;
    uint32_t dma_rx_ccr;
    uint32_t dma_rx_flags;
    uint32_t dma_rx_irq;
};

/* Starts the bus's USART (single wire, 115200 until data ID 36 says
 * otherwise) receiving into ring: by dma (its receive channel, whose
 * interrupt is enabled; the hal_port's rx_sync is dma_rx_sync on it), or,
 * with dma NULL, a byte per interrupt (QEMU has no F1 DMA model). */
void port_uart_init(struct usart_hd *usart, struct hal_rx_ring *ring, struct dma_rx *dma,
                    uint32_t pclk_hz, const struct stm32f1_bus *bus);

/* Sends by the bus's transmit channel (after port_uart_init with a dma),
 * for a hal_port whose bus is PORT_UART_BUS_ALL_DMA. */
void port_uart_send_by_dma(struct usart_hd *usart);

/* What the bus's USART and receive-DMA interrupts run (the handlers by
 * their vector names: STM32F1_BUS_DEFINED). */
void port_uart_irq(void);
void port_uart_dma_irq(void);

/* A hal_port's bus on this port: received by DMA (rx_ctx: the dma_rx), or
 * byte by byte in the USART's interrupt. */
#define PORT_UART_BUS_DMA                                                            \
    {.now_us = systick_bus_now_us, .send = usart_hd_send, .tx_done = usart_hd_tx_done, \
     .set_baud = usart_hd_set_baud, .rx_sync = dma_rx_sync}
/* ... and sent by DMA (port_uart_send_by_dma). */
#define PORT_UART_BUS_ALL_DMA                                                            \
    {.now_us = systick_bus_now_us, .send = usart_hd_send_dma, .tx_done = usart_hd_tx_done, \
     .set_baud = usart_hd_set_baud, .rx_sync = dma_rx_sync}
#define PORT_UART_BUS_INTERRUPT                                                      \
    {.now_us = systick_bus_now_us, .send = usart_hd_send, .tx_done = usart_hd_tx_done, \
     .set_baud = usart_hd_set_baud}

#endif
