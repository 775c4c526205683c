/* The bootloader on an STM32F1 board (the reference board's): the clock, the bus wire and its
 * USART with DMA receive, the flash, and the portable loop
 * (bootloader/bootloader.c). What differs from the other STM32
 * boards; the start-up path is the boards' shared one
 * (boards/common/boot_start.h). */
#include "board.h"
#include "boards/common/stm32f1/board_io.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32f1/stm32f1_bus.h"
#include "ports/stm32f1/stm32f1_uart.h"

#define BOARD_USART struct usart_hd
#define BOARD_BOOT_BUS PORT_UART_BUS_DMA
#define BOARD_CORE_HZ F103_CORE_HZ
#define board_clock_init clock_f103_init
STM32F1_BUS_DEFINED

/* No USART interrupt: its vector is not in the table. */
#define board_boot_uart_start(usart, ring, dma)                         \
    do {                                                                \
        port_uart_init((usart), (ring), (dma), BUS_USART_PCLK_HZ(F103_PCLK1_HZ, F103_PCLK2_HZ), &bus_hw); \
        usart_hd_tx_polled(usart);                                      \
    } while (0)
#define board_boot_stop_dma() (REG32(bus_hw.dma_rx_ccr) = 0) /* the bus's own channel */
#define board_boot_service usart_hd_service

#include "boards/common/boot_start.h"
