#include "port_uart.h"

#include "dma_rx.h"
#include "stm32f0_regs.h"
#include "systick_clock.h"

static struct usart_v2_hd *bus_usart;
static struct hal_rx_ring ring;
static struct dma_rx dma;

void USART1_IRQHandler(void);
void USART1_IRQHandler(void)
{
    usart_v2_hd_irq(bus_usart);
}

void DMA1_Channel2_3_IRQHandler(void);
void DMA1_Channel2_3_IRQHandler(void)
{
    DMA1_IFCR = DMA1_FLAGS(3u);
    dma_rx_lap(&dma);
}

static uint32_t now_us(void *ctx)
{
    (void)ctx;
    return systick_now_us();
}

static void uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    usart_v2_hd_send(ctx, data, len);
}

static void uart_send_polled(void *ctx, const uint8_t *data, uint16_t len)
{
    usart_v2_hd_send_polled(ctx, data, len);
}

static bool uart_tx_done(void *ctx)
{
    return usart_v2_hd_tx_done(ctx);
}

static void uart_set_baud(void *ctx, uint32_t baud)
{
    usart_v2_hd_set_baud(ctx, baud);
}

/* What both kinds of port share: all but the send. */
static void start(struct hal_port *port, struct usart_v2_hd *usart, uint32_t pclk_hz)
{
    bus_usart = usart;
    RCC_AHBENR |= RCC_AHBENR_DMA1;
    dma_rx_start(&dma, DMA1_CCR_ADDR(3u), USART1_BASE + USART_RDR_OFFSET, &ring);
    usart_v2_hd_init(usart, USART1_BASE, pclk_hz, 115200u);
    port->ctx = usart;
    port->now_us = now_us;
    port->uart_tx_done = uart_tx_done;
    port->uart_set_baud = uart_set_baud;
    port->rx = &ring;
    port->rx_sync = dma_rx_sync;
    port->rx_ctx = &dma;
}

void port_uart_init(struct hal_port *port, struct usart_v2_hd *usart, uint32_t pclk_hz)
{
    start(port, usart, pclk_hz);
    port->uart_send = uart_send;
    NVIC_ISER(0) = (1u << DMA1_CH3_IRQ) | (1u << USART1_IRQ);
}

void port_uart_init_polled(struct hal_port *port, struct usart_v2_hd *usart, uint32_t pclk_hz)
{
    start(port, usart, pclk_hz);
    port->uart_send = uart_send_polled;
    NVIC_ISER(0) = 1u << DMA1_CH3_IRQ;
}
