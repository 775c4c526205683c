/* The application's start-up path and main loop, shared by the STM32
 * boards: each board's main.c includes its board.h and port headers,
 * defines what differs, then includes this file once.
 *   BOARD_USART            the bus USART driver's state (a type)
 *   BOARD_BUS              its hal_port bus operations
 *   BOARD_CORE_HZ          the core clock, SysTick's
 *   board_clock_init()     the clock tree
 *   board_pins_init()      the bus wire's and the front end's pins
 *   board_uart_start(usart, ring, dma)  the USART, its receive DMA, its sending
 *   board_interrupts_on()  the interrupts the loop needs besides SysTick
 *   board_flash_init(f, page0, page1)  optional: a hal_flash on two pages
 *                          (else the F0/F1 flash driver's, flash_f0f1_init) */
#ifndef BOARDS_COMMON_APP_START_H
#define BOARDS_COMMON_APP_START_H

#include "app/servo.h"
#include "boards/common/app_hooks.h"
#include "ports/stm32_common/cortex_sleep.h"
#include "ports/stm32_common/fault_keep.h"
#include "ports/stm32_common/kept_ram.h"
#ifndef board_flash_init
#include "ports/stm32_common/flash_f0f1.h"
#define board_flash_init(f, page0, page1) flash_f0f1_init((f), BOARD_FLASH_PAGE, (page0), (page1))
#endif
#include "ports/stm32_common/systick_clock.h"

static struct servo servo;
static BOARD_USART usart;
static uint8_t rx_bytes[BOARD_RX_RING_BYTES];
static struct hal_rx_ring rx_ring = HAL_RX_RING_OVER(rx_bytes);
static struct dma_rx rx_dma;
static struct hal_flash flash;
static struct hal_flash fault_flash;

static const struct sensor_calibration calibration = BOARD_SENSOR_CALIBRATION;

/* The board's wiring: which driver does what, in one place. */
static const struct hal_port port = {
    .ctx = &usart,
    .bus = BOARD_BUS,
    .rx = &rx_ring,
    .rx_ctx = &rx_dma,
    .motor = BOARD_MOTOR,
    .calibration = &calibration,
    .flash = &flash,
    .fault_flash = &fault_flash,
    .serial_number = unique_id_serial,
    .reset = &_kept_ram.reset, /* reset_cause_take's, before servo_init */
    .stack_unused = &stack_unused_bytes,
    .stack_watch = stack_watch_pass,
    APP_HOOKS_PORT_FIELDS,
};

int main(void)
{
    (void)reset_cause_take();
    stack_guard_start();
    board_clock_init();
    board_pins_init();
    systick_clock_init(BOARD_CORE_HZ);
    adc_scan_init();
    pwm_bridge_init();
    board_flash_init(&flash, BOARD_CONFIG_PAGE0, BOARD_CONFIG_PAGE1);
    board_flash_init(&fault_flash, BOARD_FAULT_PAGE0, BOARD_FAULT_PAGE1);
    board_uart_start(&usart, &rx_ring, &rx_dma);
    servo_init(&servo, &port);
    board_interrupts_on();
    iwdg_start();
    for (;;) {
        servo_poll(&servo);
        iwdg_kick();
        CORTEX_SLEEP_IF(servo_may_sleep(&servo));
    }
}

#endif
