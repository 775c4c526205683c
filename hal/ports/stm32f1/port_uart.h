/* The UART and clock operations of a hal_port on an STM32F1: the servo's
 * bus on a usart_hd, its clock from SysTick. Shared by every F1 board. */
#ifndef STM32F1_PORT_UART_H
#define STM32F1_PORT_UART_H

#include "hal/hal_port.h"
#include "usart_hd.h"

enum port_uart_rx {
    PORT_UART_RX_DMA,       /* DMA1 channel 5 into the ring (silicon) */
    PORT_UART_RX_INTERRUPT, /* a byte per interrupt (QEMU has no F1 DMA model) */
};

/* Starts USART1 for the bus (single wire, 115200 until data ID 36 says
 * otherwise) receiving into the port's ring, and fills the port's now_us,
 * uart_*, rx and rx_sync (ctx: the usart). */
void port_uart_init(struct hal_port *port, struct usart_hd *usart, enum port_uart_rx rx,
                    uint32_t pclk_hz);

#endif
