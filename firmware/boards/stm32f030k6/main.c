/* The Cortex-M0 board: STM32F030K6 servo controller (pin map: README.md). */
#include "board.h"
#include "board_io.h"
#include "bootloader/app_image.h"
#include "bootloader/boot_flow.h"
#include "ports/stm32_common/boot_jump.h"
#include "ports/stm32_common/cortex_sleep.h"
#include "ports/stm32_common/flash_f0f1.h"
#include "ports/stm32f0/stm32f0_uart.h"
#include "app/servo.h"
#include "ports/stm32f0/stm32f0_regs.h"
#include "ports/stm32_common/systick_clock.h"
#include "boards/test_build.h"

static struct servo servo;
static struct usart_v2_hd usart;
static uint8_t rx_bytes[BOARD_RX_RING_BYTES];
static struct hal_rx_ring rx_ring = HAL_RX_RING_OVER(rx_bytes);
static struct dma_rx rx_dma;
static struct hal_flash flash;
static struct hal_flash fault_flash;

static const struct sensor_calibration calibration = BOARD_SENSOR_CALIBRATION;

/* Data ID 7: the version of the image the bootloader started. */
static uint16_t image_version(void *ctx)
{
    (void)ctx;
    return app_image_version_in_place(BOARD_SLOT_BASE);
}

/* UpdateEnter: the word that keeps the bootloader, then a restart. */
static void enter_bootloader(void *ctx)
{
    (void)ctx;
    boot_restart_with(BOOT_STAY_WORD_ADDR(BOARD_RAM_END), BOOT_STAY_MAGIC);
}

/* The board's wiring: which driver does what, in one place. */
static const struct hal_port port = {
    .ctx = &usart,
    .bus = PORT_UART_BUS,
    .rx = &rx_ring,
    .rx_ctx = &rx_dma,
    .motor = BOARD_MOTOR,
    .calibration = &calibration,
    .flash = &flash,
    .fault_flash = &fault_flash,
    .serial_number = unique_id_serial,
    .image_version = image_version,
    .enter_bootloader = enter_bootloader,
    .board = BOARD_ID,
    .tick_and_pass_us = BOARD_TICK_AND_PASS_US,
};

int main(void)
{
    clock_f030_init();
    bus_pins_init();
    systick_clock_init(F030_CORE_HZ);
    adc_scan_init();
    pwm_bridge_init();
    flash_f0f1_init(&flash, BOARD_FLASH_PAGE, BOARD_CONFIG_PAGE0, BOARD_CONFIG_PAGE1);
    flash_f0f1_init(&fault_flash, BOARD_FLASH_PAGE, BOARD_FAULT_PAGE0, BOARD_FAULT_PAGE1);
    port_uart_init(&usart, &rx_ring, &rx_dma, F030_PCLK_HZ, PORT_UART_SEND_DMA);
    servo_init(&servo, &port);
    iwdg_start();
    for (;;) {
        servo_poll(&servo);
        test_build_main_loop();
        iwdg_kick();
        CORTEX_SLEEP_IF(servo_may_sleep(&servo));
    }
}
