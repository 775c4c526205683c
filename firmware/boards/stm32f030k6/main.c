/* The Cortex-M0 board: STM32F030K6 servo controller (pin map: README.md). */
#include "board.h"
#include "board_f030.h"
#include "boot_flow.h"
#include "boot_jump.h"
#include "flash_f0f1.h"
#include "port_uart.h"
#include "servo.h"
#include "stm32f0_regs.h"
#include "systick_clock.h"

static struct servo servo;
static struct hal_port port;
static struct usart_v2_hd usart;
static struct hal_flash flash;

static const struct sensor_calibration calibration = BOARD_SENSOR_CALIBRATION;

/* UpdateEnter: the word that keeps the bootloader, then a restart. */
static void enter_bootloader(void *ctx)
{
    (void)ctx;
    boot_restart_with(BOOT_STAY_WORD_ADDR(BOARD_RAM_END), BOOT_STAY_MAGIC);
}

int main(void)
{
    clock_f030_init();
    bus_pins_init();
    systick_clock_init(F030_CORE_HZ);
    adc_scan_init();
    pwm_bridge_init();
    flash_f0f1_init(&flash, BOARD_FLASH_PAGE, BOARD_CONFIG_PAGE0, BOARD_CONFIG_PAGE1);
    port = (struct hal_port){
        .calibration = &calibration,
        .flash = &flash,
        .enter_bootloader = enter_bootloader,
        .board = BOARD_ID,
        .serial_number = unique_id_serial(),
    };
    board_port_motor_sensors(&port);
    port_uart_init(&port, &usart, F030_PCLK_HZ);
    servo_init(&servo, &port);
    iwdg_start();
    for (;;) {
        servo_poll(&servo);
        iwdg_kick();
    }
}
