/* The bootloader's start-up path, shared by the STM32 boards: each board's
 * boot_main.c includes its board.h and port headers, defines what differs,
 * then includes this file once.
 *   BOARD_USART                 the bus USART driver's state (a type)
 *   BOARD_BOOT_BUS              its hal_port bus operations here
 *   BOARD_CORE_HZ               the core clock, SysTick's
 *   board_clock_init()          the clock tree
 *   board_boot_uart_start(usart, ring, dma)  the USART, its receive DMA, sending polled
 *   board_boot_stop_dma()       stops the receive DMA's channel
 *   board_boot_service(usart)   optional: what the loop runs each pass
 *   board_boot_flash_init(config, slot)  optional: the config pages' and the
 *                               slot's flash (else the F0/F1 flash driver's)
 *   BOARD_RX_GAP_TOLERANCE_US   optional: hal_port.rx_gap_tolerance_us */
#ifndef BOARDS_COMMON_BOOT_START_H
#define BOARDS_COMMON_BOOT_START_H

#include "bootloader/boot_flow.h"
#include "bootloader/bootloader.h"
#include "ports/stm32_common/boot_jump.h"
#include "ports/stm32_common/flash_f0f1.h"
#include "ports/stm32_common/kept_ram.h"
#include "storage/config_peek.h"
#include "ports/stm32_common/systick_clock.h"

static BOARD_USART usart;
static uint8_t rx_bytes[BOARD_BOOT_RX_RING_BYTES];
static struct hal_rx_ring rx_ring = HAL_RX_RING_OVER(rx_bytes);
static struct dma_rx rx_dma;
static struct hal_flash config_flash;
static struct hal_flash slot_flash;
static struct app_slot slot;
/* The board's wiring for the bootloader: which driver does what. */
static const struct hal_port port = {
    .ctx = &usart,
    .bus = BOARD_BOOT_BUS,
    .rx = &rx_ring,
    .rx_ctx = &rx_dma,
    .flash = &config_flash,
#ifdef BOARD_RX_GAP_TOLERANCE_US
    .rx_gap_tolerance_us = BOARD_RX_GAP_TOLERANCE_US,
#endif
};

/* The bootloader's peripherals stop before the application takes over:
 * the DMA would go on writing into what is now the application's RAM. */
static void start_app(const struct app_slot *s)
{
    USART_CR1(BUS_USART_BASE) = 0; /* the board's bus (its port's bus header) */
    board_boot_stop_dma();
    boot_jump(s->base + APP_HEADER_SIZE);
}

#ifndef BOARD_SLOT_READ_FAILED /* a part whose flash reads always */
#define BOARD_SLOT_READ_FAILED NULL
#endif

#ifndef board_boot_flash_init
/* The same flash: any page by its address. */
static void board_boot_flash_init(struct hal_flash *config, struct hal_flash *slot_pages)
{
    flash_f0f1_init(config, BOARD_FLASH_PAGE, BOARD_CONFIG_PAGE0, BOARD_CONFIG_PAGE1);
    *slot_pages = *config;
}
#endif

#ifdef board_boot_service
static void service(void)
{
    board_boot_service(&usart);
}
#define BOOT_SERVICE service
#else
#define BOOT_SERVICE NULL
#endif

int main(void)
{
    uint32_t stay = boot_take_word(BOOT_STAY_WORD_ADDR(BOARD_RAM_END));
    uint8_t link_id;
    uint8_t link_baud;
    board_clock_init();
    bus_pins_init();
    systick_clock_init(BOARD_CORE_HZ);
    board_boot_flash_init(&config_flash, &slot_flash);
    if (!kept_link(&link_id, &link_baud)) { /* not a restart UpdateEnter made */
        config_peek_link(&config_flash, &link_id, &link_baud);
    }
    slot = (struct app_slot){.flash = &slot_flash, .base = BOARD_SLOT_BASE, .pages = BOARD_SLOT_PAGES,
                             .read_failed = BOARD_SLOT_READ_FAILED};
    board_boot_uart_start(&usart, &rx_ring, &rx_dma);
    const struct boot_board board = {.port = &port, .slot = &slot, .board = BOARD_ID,
                                     .stay_word = stay, .start_app = start_app,
                                     .link_id = link_id, .link_baud = link_baud,
                                     .service = BOOT_SERVICE};
    bootloader_run(&board);
    return 0;
}

#endif
