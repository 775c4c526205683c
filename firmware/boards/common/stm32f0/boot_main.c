/* The bootloader on the Cortex-M0 board: the clock, the bus wire and its
 * USART with DMA receive (an answer goes out whole before the loop goes
 * on), the flash, and the portable loop (bootloader/bootloader.c).
 * What differs from the other STM32 boards; the start-up path is the
 * boards' shared one (boards/common/boot_start.h). */
#include "board.h"
#include "boards/common/stm32f0/board_io.h"
#include "ports/stm32f0/stm32f0_regs.h"
#include "ports/stm32f0/stm32f0_bus.h"
#include "ports/stm32f0/stm32f0_uart.h"

#define BOARD_USART struct usart_v2_hd
#define BOARD_BOOT_BUS PORT_UART_BUS_POLLED
#define BOARD_CORE_HZ F030_CORE_HZ
#define board_clock_init clock_f030_init
#define board_boot_uart_start(usart, ring, dma) \
    port_uart_init((usart), (ring), (dma), F030_PCLK_HZ, PORT_UART_SEND_POLLED)
#define board_boot_stop_dma() (REG32(DMA1_CCR_ADDR(3u)) = 0)

#include "boards/common/boot_start.h"
