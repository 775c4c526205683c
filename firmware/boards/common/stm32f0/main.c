/* An STM32F030 servo board (Cortex-M0; the reference one, stm32f030k6: its
 * README.md), its pins from its board.h. What differs from the other STM32
 * boards; the start-up path and the main loop are the boards' shared one
 * (boards/common/app_start.h). */
#include "board.h"
#include "boards/common/stm32f0/board_io.h"
#include "ports/stm32f0/stm32f0_regs.h"
#include "ports/stm32f0/stm32f0_bus.h"
#include "ports/stm32f0/stm32f0_uart.h"

#define BOARD_USART struct usart_v2_hd
#define BOARD_BUS PORT_UART_BUS
#define BOARD_CORE_HZ F030_CORE_HZ
#define board_clock_init clock_f030_init
#define board_pins_init bus_pins_init
#define board_uart_start(usart, ring, dma) \
    port_uart_init((usart), (ring), (dma), F030_PCLK_HZ, PORT_UART_SEND_DMA)
#define board_interrupts_on() ((void)0) /* the USART's is the port's to enable */

#include "boards/common/app_start.h"
