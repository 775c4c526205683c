/* The bootloader on the reference board: the clock, the bus wire and its
 * USART with DMA receive, the flash, and the portable loop
 * (firmware/bootloader/bootloader.c). */
#include "board.h"
#include "board_io.h"
#include "bootloader/boot_flow.h"
#include "ports/stm32_common/boot_jump.h"
#include "bootloader/bootloader.h"
#include "ports/stm32_common/flash_f0f1.h"
#include "ports/stm32f1/stm32f1_uart.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32_common/systick_clock.h"

static struct usart_hd usart;
static uint8_t rx_bytes[BOARD_BOOT_RX_RING_BYTES];
static struct hal_rx_ring rx_ring = HAL_RX_RING_OVER(rx_bytes);
static struct dma_rx rx_dma;
static struct hal_flash config_flash;
static struct hal_flash slot_flash;
static struct app_slot slot;
/* The board's wiring for the bootloader: which driver does what. */
static const struct hal_port port = {
    .ctx = &usart,
    .bus = PORT_UART_BUS_DMA,
    .rx = &rx_ring,
    .rx_ctx = &rx_dma,
    .flash = &config_flash,
};

/* The bootloader's peripherals stop before the application takes over:
 * the DMA would go on writing into what is now the application's RAM. */
static void start_app(const struct app_slot *s)
{
    USART_CR1(USART1_BASE) = 0;
    REG32(DMA1_CCR5_ADDR) = 0;
    boot_jump(s->base + APP_HEADER_SIZE);
}

static void service(void)
{
    usart_hd_service(&usart);
}

int main(void)
{
    uint32_t stay = boot_take_word(BOOT_STAY_WORD_ADDR(BOARD_RAM_END));
    clock_f103_init();
    bus_pins_init();
    systick_clock_init(F103_CORE_HZ);
    flash_f0f1_init(&config_flash, BOARD_FLASH_PAGE, BOARD_CONFIG_PAGE0, BOARD_CONFIG_PAGE1);
    slot_flash = config_flash; /* the same flash: any page by its address */
    slot = (struct app_slot){.flash = &slot_flash, .base = BOARD_SLOT_BASE, .pages = BOARD_SLOT_PAGES};
    port_uart_init(&usart, &rx_ring, &rx_dma, F103_PCLK2_HZ);
    usart_hd_tx_polled(&usart); /* no USART interrupt: its vector is not in the table */
    const struct boot_board board = {.port = &port, .slot = &slot, .board = BOARD_ID,
                                     .stay_word = stay, .start_app = start_app,
                                     .service = service};
    bootloader_run(&board);
    return 0;
}
