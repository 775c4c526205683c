/* The bootloader on QEMU's stm32vldiscovery. QEMU models no flash
 * controller, so the slot is read-only here: this image checks the
 * application and starts it, as the board's does; updates are the
 * simulator's and the reference board's. The application keeps its config
 * store in RAM on this board, so the bootloader finds none there (QEMU's
 * unwritten flash reads 0) and answers at the factory ID and baud rate. */
#include "board.h"
#include "bootloader/boot_flow.h"
#include "ports/stm32_common/boot_jump.h"
#include "bootloader/bootloader.h"
#include "ports/stm32f1/stm32f1_uart.h"
#include "qemu_board.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32_common/systick_clock.h"

static struct usart_hd usart;
static uint8_t rx_bytes[BOARD_BOOT_RX_RING_BYTES];
static struct hal_rx_ring rx_ring = HAL_RX_RING_OVER(rx_bytes);
static struct hal_flash config_flash;
static struct hal_flash slot_flash;
static struct app_slot slot;
/* The board's wiring for the bootloader: which driver does what. */
static const struct hal_port port = {
    .ctx = &usart,
    .bus = PORT_UART_BUS_INTERRUPT,
    .rx = &rx_ring,
    .flash = &config_flash,
    .rx_gap_tolerance_us = QEMU_RX_GAP_TOLERANCE_US,
};

static bool refuse_erase(void *ctx, uint32_t addr)
{
    (void)ctx;
    (void)addr;
    return false;
}

static bool refuse_program(void *ctx, uint32_t addr, const uint8_t *data)
{
    (void)ctx;
    (void)addr;
    (void)data;
    return false;
}

static void flash_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    const volatile uint8_t *src = (const volatile uint8_t *)(uintptr_t)addr;
    for (uint32_t i = 0; i < len; i++) {
        dst[i] = src[i];
    }
}

static void start_app(const struct app_slot *s)
{
    USART_CR1(USART1_BASE) = 0;
    boot_jump(s->base + APP_HEADER_SIZE);
}

static void service(void)
{
    usart_hd_service(&usart); /* QEMU's USART raises no transmit interrupts */
    usart_hd_irq(&usart);     /* and the receive interrupt is not in the table */
}

int main(void)
{
    uint32_t stay = boot_take_word(BOOT_STAY_WORD_ADDR(BOARD_RAM_END));
    systick_clock_init(QEMU_CORE_HZ);
    slot_flash = (struct hal_flash){.page_size = 1024u, .erase_page = refuse_erase,
                                    .write_block = 2, .program = refuse_program, .read = flash_read};
    config_flash = slot_flash; /* the application's store is in its RAM: none here */
    config_flash.page_addr[0] = 0x0801F800u;
    config_flash.page_addr[1] = 0x0801FC00u;
    slot = (struct app_slot){.flash = &slot_flash, .base = BOARD_SLOT_BASE, .pages = BOARD_SLOT_PAGES};
    port_uart_init(&usart, &rx_ring, NULL, QEMU_CORE_HZ); /* no DMA model: by interrupt */
    usart_hd_tx_polled(&usart);
    usart_hd_no_echo(&usart);
    const struct boot_board board = {.port = &port, .slot = &slot, .board = BOARD_ID,
                                     .stay_word = stay, .start_app = start_app, .service = service};
    bootloader_run(&board);
    return 0;
}
