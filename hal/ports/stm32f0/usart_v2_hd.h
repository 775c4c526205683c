/* The F0's USART (RM0360 23: separate status, clear, receive and transmit
 * registers) in single-wire half-duplex mode. It receives by DMA only
 * (dma_rx.h, channel 3): no code runs per received byte. A send runs from
 * the interrupt and turns the line around (receiver off while sending,
 * back on after the last stop bit), so the servo never hears its own echo,
 * as on the F1 (../stm32f1/usart_hd.h). The bootloader sends from its
 * main loop instead (usart_v2_hd_send_polled). */
#ifndef STM32F0_USART_V2_HD_H
#define STM32F0_USART_V2_HD_H

#include <stdbool.h>
#include <stdint.h>

struct usart_v2_hd {
    uintptr_t base;
    uint32_t pclk_hz;
    uintptr_t tx_dma; /* the DMA channel that sends (dma_tx.h) */
    volatile uint8_t tx_busy;
};

/* Single wire, 16x oversampling, the receiver requesting DMA (the caller
 * starts the channel on USART_RDR), the transmitter served by the DMA
 * channel tx_dma (0: none, usart_v2_hd_send_polled only). */
void usart_v2_hd_init(struct usart_v2_hd *u, uintptr_t base, uint32_t pclk_hz, uint32_t baud,
                      uintptr_t tx_dma);
/* usart: the struct usart_v2_hd, here and in send, send_polled and
 * tx_done, so that a hal_port's bus names these directly (stm32f0_uart.h). */
void usart_v2_hd_set_baud(void *usart, uint32_t baud);
/* Starts sending by DMA; data must stay valid until usart_v2_hd_tx_done(). */
void usart_v2_hd_send(void *usart, const uint8_t *data, uint16_t len);
bool usart_v2_hd_tx_done(void *usart);
/* The USART's interrupt handler calls this. */
void usart_v2_hd_irq(struct usart_v2_hd *u);
/* The whole of data, waiting for each byte and for the last stop bit, so
 * no interrupt is needed: for a main loop that has nothing else to do
 * meanwhile (the bootloader's; its 4 KB have no room for more). */
void usart_v2_hd_send_polled(void *usart, const uint8_t *data, uint16_t len);

#endif
