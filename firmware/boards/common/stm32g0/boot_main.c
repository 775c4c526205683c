/* The bootloader on the STM32G031K8 board: the clock, the bus wire and its
 * USART with DMA receive (an answer goes out whole before the loop goes
 * on), the flash (64-bit units), and the portable loop
 * (bootloader/bootloader.c). The start-up path is the boards' shared one
 * (boards/common/boot_start.h). */
#include "board.h"
#include "boards/common/stm32g0/board_io.h"
#include "ports/stm32g0/flash_g0.h"
#include "ports/stm32g0/stm32g0_bus.h"
#include "ports/stm32g0/stm32g0_uart.h"

static struct flash_g0 flash_chip = {.base = BOARD_FLASH_BASE, .page_size = BOARD_FLASH_PAGE,
                                     .pages = BOARD_FLASH_PAGES};
static const struct g0_bus bus = G0_BUS_FROM_BOARD;

#define BOARD_USART struct usart_v2_hd
#define BOARD_BOOT_BUS G0_UART_BUS_POLLED
#define BOARD_CORE_HZ G031_CORE_HZ
#define board_clock_init clock_g031_init
#define board_boot_uart_start(usart, ring, dma) \
    g0_uart_init((usart), (ring), (dma), &bus, G031_PCLK_HZ, G0_UART_SEND_POLLED)
#define board_boot_stop_dma() (DMA_CCR(DMA1_CCR_ADDR(BOARD_BUS_DMA_RX)) = 0)

/* The config pages and the slot: the same flash, any page by its number. */
static void g0_boot_flash_init(struct hal_flash *config, struct hal_flash *slot_pages)
{
    flash_g0_init(config, &flash_chip, BOARD_CONFIG_PAGE0, BOARD_CONFIG_PAGE1);
    *slot_pages = *config;
}
#define board_boot_flash_init g0_boot_flash_init
#define BOARD_SLOT_READ_FAILED flash_g0_read_failed

#include "boards/common/boot_start.h"
