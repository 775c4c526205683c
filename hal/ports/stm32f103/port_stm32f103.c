/* STM32F103 port, board-stub stage: the clock, the receive interrupt and
 * the unique ID are real; UART transmit, PWM, encoder and flash writes are
 * stubs until the MCU port lands (issue 6), so the image links and sizes the
 * whole core. */
#include <stdint.h>

#include "calibration.h"
#include "port_stm32f103.h"

#define REG32(addr) (*(volatile uint32_t *)(addr))

#define SYSTICK_CTRL 0xE000E010u
#define SYSTICK_LOAD 0xE000E014u
#define SYSTICK_VAL 0xE000E018u
#define USART1_SR 0x40013800u
#define USART1_DR 0x40013804u
#define UID_BASE 0x1FFFF7E8u
#define CORE_HZ 8000000u /* HSI until the clock tree is set up */
#define USART_SR_RXNE (1u << 5)

static volatile uint32_t uptime_ms;
static struct servo *rx_servo;

void SysTick_Handler(void);
void USART1_IRQHandler(void);

void SysTick_Handler(void)
{
    uptime_ms++;
}

static uint32_t now_us(void *ctx)
{
    (void)ctx;
    uint32_t ms;
    uint32_t val;
    do {
        ms = uptime_ms;
        val = REG32(SYSTICK_VAL);
    } while (ms != uptime_ms);
    uint32_t ticks_per_us = CORE_HZ / 1000000u;
    return ms * 1000u + (REG32(SYSTICK_LOAD) - val) / ticks_per_us;
}

void USART1_IRQHandler(void)
{
    if ((REG32(USART1_SR) & USART_SR_RXNE) && rx_servo != 0) {
        servo_on_rx_byte(rx_servo, (uint8_t)REG32(USART1_DR), now_us(0));
    }
}

static void uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    (void)ctx;
    (void)data;
    (void)len; /* stub: transmit lands with the MCU port */
}

static bool uart_tx_done(void *ctx)
{
    (void)ctx;
    return true;
}

static void uart_set_baud(void *ctx, uint32_t baud)
{
    (void)ctx;
    (void)baud; /* stub */
}

static void motor_drive(void *ctx, int16_t duty)
{
    (void)ctx;
    (void)duty; /* stub: PWM lands with the MCU port */
}

static void motor_coast(void *ctx)
{
    (void)ctx; /* stub */
}

static uint16_t encoder_read(void *ctx)
{
    (void)ctx;
    return 0; /* stub: ADC lands with the MCU port */
}

static void sensors_read(void *ctx, struct sensor_raw *out)
{
    (void)ctx;
    *out = (struct sensor_raw){0}; /* stub: ADC lands with the MCU port */
}

static const struct sensor_calibration calibration = {
    .supply_uv_per_count = BOARD_SUPPLY_UV_PER_COUNT,
    .current_ua_per_count = BOARD_CURRENT_UA_PER_COUNT,
    .current_zero_counts = BOARD_CURRENT_ZERO_COUNTS,
};

static bool flash_erase(void *ctx, uint32_t addr)
{
    (void)ctx;
    (void)addr;
    return false; /* stub: the store keeps factory values */
}

static bool flash_program(void *ctx, uint32_t addr, uint16_t value)
{
    (void)ctx;
    (void)addr;
    (void)value;
    return false; /* stub */
}

static void flash_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    const volatile uint8_t *src = (const volatile uint8_t *)addr;
    for (uint32_t i = 0; i < len; i++) {
        dst[i] = src[i];
    }
}

static const struct hal_flash flash = {
    .page_size = 1024u,
    .page_addr = {0x0800F800u, 0x0800FC00u},
    .erase_page = flash_erase,
    .program_u16 = flash_program,
    .read = flash_read,
};

/* Data ID 8: the 96-bit unique ID folded to 32 bits. */
static uint32_t serial_from_uid(void)
{
    return REG32(UID_BASE) ^ REG32(UID_BASE + 4u) ^ REG32(UID_BASE + 8u);
}

void port_init(struct hal_port *port, struct servo *servo)
{
    *port = (struct hal_port){
        .now_us = now_us,
        .uart_send = uart_send,
        .uart_tx_done = uart_tx_done,
        .uart_set_baud = uart_set_baud,
        .motor_drive = motor_drive,
        .motor_coast = motor_coast,
        .encoder_read = encoder_read,
        .sensors_read = sensors_read,
        .calibration = &calibration,
        .flash = &flash,
        .serial_number = serial_from_uid(),
    };
    rx_servo = servo;
    REG32(SYSTICK_LOAD) = CORE_HZ / 1000u - 1u;
    REG32(SYSTICK_VAL) = 0;
    REG32(SYSTICK_CTRL) = 7u; /* core clock, interrupt, enable */
}
