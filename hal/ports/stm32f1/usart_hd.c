#include "ports/stm32f1/usart_hd.h"

#include "ports/stm32_common/dma_tx.h"
#include "ports/stm32f1/stm32f1_regs.h"

/* 16x oversampling: BRR is the divider in 1/16ths, i.e. pclk / baud. */
static void set_brr(const struct usart_hd *u, uint32_t baud)
{
    USART_BRR(u->base) = (u->pclk_hz + baud / 2u) / baud;
}

void usart_hd_set_baud(void *usart, uint32_t baud)
{
    set_brr(usart, baud);
}

void usart_hd_init(struct usart_hd *u, uintptr_t base, uint32_t pclk_hz, uint32_t baud,
                   bool single_wire, struct hal_rx_ring *rx, uint32_t (*clock_us)(void))
{
    u->base = base;
    u->tx_irq = true;
    u->hears_own_bytes = single_wire;
    u->pclk_hz = pclk_hz;
    u->tx = 0;
    u->tx_left = 0;
    u->tx_busy = 0;
    u->rx_dma = false;
    u->tx_dma = 0;
    u->rx = rx;
    u->clock_us = clock_us;
    USART_CR1(base) = 0;
    set_brr(u, baud);
    USART_CR3(base) = single_wire ? USART_CR3_HDSEL : 0u;
    /* Clear the status flags. On silicon this only clears stale flags; QEMU
     * (7.2) misplaces TXE in its reset value and reports it only once SR has
     * been written. */
    USART_SR(base) = 0;
    USART_CR1(base) = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_RXNEIE;
}

void usart_hd_rx_dma(struct usart_hd *u)
{
    u->rx_dma = true;
    USART_CR3(u->base) |= USART_CR3_DMAR;
    /* The DMA takes the bytes; the line going idle after them is what
     * wakes a sleeping main loop to frame them. */
    USART_CR1(u->base) = (USART_CR1(u->base) & ~USART_CR1_RXNEIE) | USART_CR1_IDLEIE;
}

void usart_hd_tx_dma(struct usart_hd *u, uintptr_t channel)
{
    u->tx_dma = channel;
    dma_tx_init(channel, u->base + USART_DR_OFFSET);
    USART_CR3(u->base) |= USART_CR3_DMAT;
    /* What CR1 holds while sending, worked out once: an answer's path is
     * short on the Cortex-M0 (30 us). Nothing else changes CR1 meanwhile. */
    uint32_t cr1 = USART_CR1(u->base) | USART_CR1_TCIE;
    u->cr1_sending = u->hears_own_bytes ? cr1 & ~USART_CR1_RE : cr1;
}

void usart_hd_tx_polled(struct usart_hd *u)
{
    u->tx_irq = false;
}

void usart_hd_no_echo(struct usart_hd *u)
{
    u->hears_own_bytes = false;
}

void usart_hd_send(void *usart, const uint8_t *data, uint16_t len)
{
    struct usart_hd *u = usart;
    if (len == 0u) {
        return;
    }
    u->tx = data;
    u->tx_left = len;
    u->tx_busy = 1;
    /* Turn the line around: stop listening, start talking. TXEIE and TCIE
     * also mark the transmit phase when the main loop does the work. */
    uint32_t cr1 = USART_CR1(u->base);
    if (u->hears_own_bytes) {
        cr1 &= ~USART_CR1_RE;
    }
    USART_CR1(u->base) = u->tx_irq ? (cr1 | USART_CR1_TXEIE) : cr1;
}

void usart_hd_send_dma(void *usart, const uint8_t *data, uint16_t len)
{
    struct usart_hd *u = usart;
    if (len == 0u) {
        return;
    }
    u->tx_busy = 1;
    /* TC cleared (rc_w0; the other flags ignore a 1), so that it sets only
     * after the last byte's stop bit, and the interrupt comes then. */
    USART_SR(u->base) = ~USART_SR_TC;
    USART_CR1(u->base) = u->cr1_sending;
    dma_tx_start(u->tx_dma, data, len);
}

/* One step of a transmission: the next byte while the data register is
 * empty, then the stop bit of the last one, then the line turned around. */
static void transmit_step(struct usart_hd *u, uint32_t sr)
{
    uint32_t cr1 = USART_CR1(u->base);
    if (u->tx_left > 0u) {
        if (sr & USART_SR_TXE) {
            USART_DR(u->base) = *u->tx;
            u->tx++;
            u->tx_left--;
            if (u->tx_left == 0u && u->tx_irq) {
                /* Last byte in the shifter: wait for its stop bit. */
                USART_CR1(u->base) = (cr1 & ~USART_CR1_TXEIE) | USART_CR1_TCIE;
            }
        }
    } else if (sr & USART_SR_TC) {
        USART_CR1(u->base) = (cr1 & ~(USART_CR1_TCIE | USART_CR1_TXEIE)) | USART_CR1_RE;
        if (u->tx_dma != 0u) {
            dma_tx_stop(u->tx_dma);
        }
        u->tx_busy = 0;
    }
}

void usart_hd_service(struct usart_hd *u)
{
    if (u->tx_irq) {
        return;
    }
    /* As far as the flags allow now: a model that completes each byte at
     * once gets the whole frame and the line turned around in one call, so
     * no reply of the host's finds the receiver still off. */
    while (u->tx_busy) {
        uint32_t sr = USART_SR(u->base);
        if (!(sr & (u->tx_left > 0u ? USART_SR_TXE : USART_SR_TC))) {
            return;
        }
        transmit_step(u, sr);
    }
}

bool usart_hd_tx_done(void *usart)
{
    return !((const struct usart_hd *)usart)->tx_busy;
}

/* Receive interrupt, without DMA. Drain: on silicon this sees one byte
 * (two at most, bytes are 87 us apart at 115200). QEMU 7.2 can hand over
 * the next byte while DR is read and lower the interrupt after it, so a
 * byte would wait unseen. */
static uint32_t receive_bytes(struct usart_hd *u, uint32_t sr, uint32_t cr1)
{
    while (sr & (USART_SR_RXNE | USART_SR_ORE)) {
        uint8_t byte = (uint8_t)USART_DR(u->base); /* also clears an overrun */
        if (sr & USART_SR_ORE) {
            u->rx->overruns++; /* a byte came before the last was read */
        }
        if ((sr & USART_SR_RXNE) && (cr1 & USART_CR1_RE)) {
            hal_rx_ring_put(u->rx, byte, u->clock_us());
        }
        sr = USART_SR(u->base);
    }
    return sr;
}

void usart_hd_irq(struct usart_hd *u)
{
    uint32_t sr = USART_SR(u->base);
    uint32_t cr1 = USART_CR1(u->base);
    if (!u->rx_dma) {
        sr = receive_bytes(u, sr, cr1);
    } else if ((sr & USART_SR_IDLE) && !(sr & USART_SR_RXNE)) {
        /* Cleared by SR then DR read (RM0008 27.6.1). Not while a byte
         * waits for the DMA: that read would take it; the flag then stays
         * and the interrupt comes again once the DMA has it. */
        (void)USART_DR(u->base);
    }
    if (u->tx_irq && (cr1 & (USART_CR1_TXEIE | USART_CR1_TCIE))) {
        transmit_step(u, sr);
    }
}
