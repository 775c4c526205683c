#include "ports/stm32f0/usart_v2_hd.h"

#include "ports/stm32_common/dma_tx.h"
#include "ports/stm32f0/stm32f0_regs.h"

/* Receiving: the DMA takes the bytes, the line going idle after them
 * wakes a sleeping main loop to frame them. */
enum { RUNNING = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_IDLEIE };
enum { SENDING = RUNNING & ~(USART_CR1_RE | USART_CR1_IDLEIE) };

/* 16x oversampling: BRR is the divider in 1/16ths, i.e. pclk / baud. */
static uint32_t brr(uint32_t pclk_hz, uint32_t baud)
{
    return (pclk_hz + baud / 2u) / baud;
}

void usart_v2_hd_set_baud(void *usart, uint32_t baud)
{
    struct usart_v2_hd *u = usart;
    /* BRR and the mode bits take writes only while the USART is off
     * (RM0360 23.7.4): a byte on the wire now is lost, as with any
     * baud change (data ID 36 answers first, then changes). */
    uint32_t cr1 = USART_CR1(u->base);
    USART_CR1(u->base) = 0;
    USART_BRR(u->base) = brr(u->pclk_hz, baud);
    USART_CR1(u->base) = cr1;
}

void usart_v2_hd_init(struct usart_v2_hd *u, uintptr_t base, uint32_t pclk_hz, uint32_t baud,
                      uintptr_t tx_dma)
{
    *u = (struct usart_v2_hd){.base = base, .pclk_hz = pclk_hz, .tx_dma = tx_dma};
    USART_CR1(base) = 0;
    USART_BRR(base) = brr(pclk_hz, baud);
    /* An overrun cannot happen while the DMA takes every byte; were the
     * bus's DMA ever held up, OVRDIS keeps the receiver going (the newest
     * byte wins) instead of stopping it until the flag is cleared. */
    USART_CR3(base) = USART_CR3_HDSEL | USART_CR3_DMAR | USART_CR3_OVRDIS | (tx_dma != 0u ? USART_CR3_DMAT : 0u);
    USART_ICR(base) = USART_ICR_CLEAR;
    if (tx_dma != 0u) {
        dma_tx_init(tx_dma, base + USART_TDR_OFFSET);
    }
    USART_CR1(base) = RUNNING;
}

void usart_v2_hd_send(void *usart, const uint8_t *data, uint16_t len)
{
    struct usart_v2_hd *u = usart;
    if (len == 0u) {
        return;
    }
    u->tx_busy = 1;
    /* Turn the line around: stop listening, then talk. TC is cleared
     * first, so it sets only after the last byte's stop bit. */
    USART_ICR(u->base) = USART_ICR_TCCF;
    USART_CR1(u->base) = SENDING | USART_CR1_TCIE;
    dma_tx_start(u->tx_dma, data, len);
}

void usart_v2_hd_send_polled(void *usart, const uint8_t *data, uint16_t len)
{
    struct usart_v2_hd *u = usart;
    if (len == 0u) {
        return; /* TC, cleared after the last send, would never come */
    }
    USART_CR1(u->base) = SENDING;
    for (uint16_t i = 0; i < len; i++) {
        while (!(USART_ISR(u->base) & USART_ISR_TXE)) {
        }
        USART_TDR(u->base) = data[i];
    }
    while (!(USART_ISR(u->base) & USART_ISR_TC)) {
    }
    USART_ICR(u->base) = USART_ICR_CLEAR;
    USART_CR1(u->base) = RUNNING;
}

bool usart_v2_hd_tx_done(void *usart)
{
    return !((const struct usart_v2_hd *)usart)->tx_busy;
}

/* The line gone idle after a request (it woke the main loop), and the last
 * byte of an answer sent: the line turned around. */
void usart_v2_hd_irq(struct usart_v2_hd *u)
{
    uint32_t isr = USART_ISR(u->base);
    if (isr & USART_ISR_IDLE) {
        USART_ICR(u->base) = USART_ICR_IDLECF;
    }
    if (u->tx_busy && (isr & USART_ISR_TC)) {
        USART_ICR(u->base) = USART_ICR_CLEAR;
        USART_CR1(u->base) = RUNNING;
        dma_tx_stop(u->tx_dma);
        u->tx_busy = 0;
    }
}
