/* The UART and clock operations of a hal_port on an STM32F0: the servo's
 * bus on USART1 (usart_v2_hd.h) received by DMA1 channel 3, its clock from
 * SysTick. */
#ifndef STM32F0_PORT_UART_H
#define STM32F0_PORT_UART_H

#include "hal/hal_port.h"
#include "usart_v2_hd.h"

/* Starts USART1 for the bus (single wire, 115200 until data ID 36 says
 * otherwise) receiving into the port's ring, and fills the port's now_us,
 * uart_*, rx, rx_sync and rx_ctx (ctx: the usart). Sends from the USART's
 * interrupt; enables it and the DMA's. */
void port_uart_init(struct hal_port *port, struct usart_v2_hd *usart, uint32_t pclk_hz);
/* The same for the bootloader, whose vector table has no USART entry: an
 * answer goes out whole from its main loop (usart_v2_hd_send_polled); only
 * the DMA's interrupt. */
void port_uart_init_polled(struct hal_port *port, struct usart_v2_hd *usart, uint32_t pclk_hz);

#endif
