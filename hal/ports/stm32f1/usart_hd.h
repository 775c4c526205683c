/* USART in single-wire half-duplex mode, interrupt-driven both ways: every
 * received byte goes to on_byte from the interrupt; a send runs from the
 * interrupt too and turns the line around (receiver off while sending, back
 * on after the last stop bit), so the servo never hears its own echo. */
#ifndef STM32F1_USART_HD_H
#define STM32F1_USART_HD_H

#include <stdbool.h>
#include <stdint.h>

struct usart_hd {
    uint32_t base;
    bool tx_irq;                 /* transmit from the interrupt (else usart_hd_service) */
    bool hears_own_bytes;        /* single wire: receiver off while sending */
    uint32_t pclk_hz;
    const uint8_t *volatile tx;
    volatile uint16_t tx_left;
    volatile uint8_t tx_busy;
    void (*on_byte)(void *ctx, uint8_t byte);
    void *ctx;
};

void usart_hd_init(struct usart_hd *u, uint32_t base, uint32_t pclk_hz, uint32_t baud,
                   bool single_wire, void (*on_byte)(void *ctx, uint8_t byte), void *ctx);
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
void usart_hd_set_baud(struct usart_hd *u, uint32_t baud);
/* Starts sending; data must stay valid until usart_hd_tx_done(). */
void usart_hd_send(struct usart_hd *u, const uint8_t *data, uint16_t len);
bool usart_hd_tx_done(const struct usart_hd *u);
/* The USART's interrupt handler calls this. */
void usart_hd_irq(struct usart_hd *u);

#endif
