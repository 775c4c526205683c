/* An STM32G031 servo board (Cortex-M0+), its pins from its board.h. What
 * differs from the other STM32 boards: its USART's DMAMUX routing, its
 * flash (64-bit units, pages by number); the start-up path and the main loop are the boards' shared one
 * (boards/common/app_start.h). */
#include "board.h"
#include "boards/common/stm32g0/board_io.h"
#include "ports/stm32g0/flash_g0.h"
#include "ports/stm32g0/stm32g0_bus.h"
#include "ports/stm32g0/stm32g0_uart.h"

static struct flash_g0 flash_chip = {.base = BOARD_FLASH_BASE, .page_size = BOARD_FLASH_PAGE,
                                     .pages = BOARD_FLASH_PAGES};
static const struct g0_bus bus = G0_BUS_FROM_BOARD;

#define BOARD_USART struct usart_v2_hd
#define BOARD_BUS G0_UART_BUS
#define BOARD_CORE_HZ G031_CORE_HZ
#define board_clock_init clock_g031_init
#define board_pins_init bus_pins_init
#define board_uart_start(usart, ring, dma) \
    g0_uart_init((usart), (ring), (dma), &bus, G031_PCLK_HZ, G0_UART_SEND_DMA)
#define board_interrupts_on() ((void)0) /* the USART's is the port's to enable */
#define board_flash_init(f, page0, page1) flash_g0_init((f), &flash_chip, (page0), (page1))

#include "boards/common/app_start.h"
