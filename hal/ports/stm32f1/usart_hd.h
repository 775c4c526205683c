/* USART in single-wire half-duplex mode. Received bytes go into the HAL's
 * ring: by DMA (dma_rx.h), with no receive interrupt at all (the main loop
 * reads the DMA's counter and notes when bytes came), or by the receive
 * interrupt a byte at a time where there is no DMA (QEMU's USART). A send runs from the interrupt and turns the line around
 * (receiver off while sending, back on after the last stop bit), so the
 * servo never hears its own echo. */
#ifndef STM32F1_USART_HD_H
#define STM32F1_USART_HD_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_rx_ring.h"

struct usart_hd {
    uintptr_t base;
    bool tx_irq;                 /* transmit from the interrupt (else usart_hd_service) */
    bool hears_own_bytes;        /* single wire: receiver off while sending */
    uint32_t pclk_hz;
    const uint8_t *volatile tx;
    volatile uint16_t tx_left;
    volatile uint8_t tx_busy;
    bool rx_dma;                 /* a DMA channel receives: the interrupt marks idle lines */
    uintptr_t tx_dma;            /* a DMA channel sends (dma_tx.h), or 0 */
    uint32_t cr1_sending;        /* CR1 while it does */
    struct hal_rx_ring *rx;
    uint32_t (*clock_us)(void);  /* stamps bytes the receive interrupt takes */
};

void usart_hd_init(struct usart_hd *u, uintptr_t base, uint32_t pclk_hz, uint32_t baud,
                   bool single_wire, struct hal_rx_ring *rx, uint32_t (*clock_us)(void));
/* Receive by DMA from now on (the caller starts the channel, dma_rx.h):
 * the USART requests DMA and raises no receive interrupt. */
void usart_hd_rx_dma(struct usart_hd *u);
/* Transmit by DMA (usart_hd_send_dma) on this channel: it moves the bytes,
 * the interrupt comes once, when the last has left (TC). */
void usart_hd_tx_dma(struct usart_hd *u, uintptr_t channel);
/* Starts sending by DMA; data must stay valid until usart_hd_tx_done(). */
void usart_hd_send_dma(void *usart, const uint8_t *data, uint16_t len);
/* Transmit from the main loop instead (usart_hd_service), for USART models
 * that raise no transmit interrupts (QEMU 7.2). Receive stays on the
 * interrupt. */
void usart_hd_tx_polled(struct usart_hd *u);
/* The main loop's share of a polled transmission; nothing to do otherwise. */
void usart_hd_service(struct usart_hd *u);
/* A link that does not echo what the servo sends (QEMU's serial socket):
 * the receiver stays on while sending. QEMU 7.2 drops input that arrives
 * while it is off, and a reply's last byte can be answered before the line
 * would have been turned around. */
void usart_hd_no_echo(struct usart_hd *u);
/* usart: the struct usart_hd, here and in send, send_dma and tx_done, so
 * that a hal_port's bus names these directly (stm32f1_uart.h). */
void usart_hd_set_baud(void *usart, uint32_t baud);
/* Starts sending; data must stay valid until usart_hd_tx_done(). */
void usart_hd_send(void *usart, const uint8_t *data, uint16_t len);
bool usart_hd_tx_done(void *usart);
/* The USART's interrupt handler calls this. */
void usart_hd_irq(struct usart_hd *u);

#endif
