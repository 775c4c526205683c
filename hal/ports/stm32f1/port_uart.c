#include "port_uart.h"

#include "stm32f1_regs.h"
#include "systick_clock.h"

static struct usart_hd *bus_usart;
static hal_rx_byte_fn rx_to;

void USART1_IRQHandler(void);
void USART1_IRQHandler(void)
{
    usart_hd_irq(bus_usart);
}

static void on_byte(void *ctx, uint8_t byte)
{
    rx_to(ctx, byte, systick_now_us());
}

static uint32_t now_us(void *ctx)
{
    (void)ctx;
    return systick_now_us();
}

static void uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    usart_hd_send(ctx, data, len);
}

static bool uart_tx_done(void *ctx)
{
    return usart_hd_tx_done(ctx);
}

static void uart_set_baud(void *ctx, uint32_t baud)
{
    usart_hd_set_baud(ctx, baud);
}

void port_uart_init(struct hal_port *port, struct usart_hd *usart, hal_rx_byte_fn on_rx,
                    void *rx_ctx, uint32_t pclk_hz)
{
    bus_usart = usart;
    rx_to = on_rx;
    usart_hd_init(usart, USART1_BASE, pclk_hz, 115200u, true, on_byte, rx_ctx);
    port->ctx = usart;
    port->now_us = now_us;
    port->uart_send = uart_send;
    port->uart_tx_done = uart_tx_done;
    port->uart_set_baud = uart_set_baud;
}
