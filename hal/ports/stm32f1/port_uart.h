/* The UART and clock operations of a hal_port on an STM32F1: the servo's
 * bus on a usart_hd, its clock from SysTick. Shared by every F1 board. */
#ifndef STM32F1_PORT_UART_H
#define STM32F1_PORT_UART_H

#include "hal/hal_port.h"
#include "usart_hd.h"

/* Starts USART1 for the bus (single wire, 115200 until data ID 36 says
 * otherwise), hands every received byte to on_rx(rx_ctx, ...), and fills
 * the port's now_us and uart_* operations (ctx: the usart). */
void port_uart_init(struct hal_port *port, struct usart_hd *usart, hal_rx_byte_fn on_rx,
                    void *rx_ctx, uint32_t pclk_hz);

#endif
