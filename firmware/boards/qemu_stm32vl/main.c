/* The servo on QEMU's stm32vldiscovery (STM32F100): the real USART driver
 * and the real core; motor, sensors and flash come from models compiled into
 * the image, since QEMU has no ADC, timers or flash controller for it. */
#include "board.h"
#include "plant_fixed.h"
#include "qemu_board.h"
#include "app/servo.h"
#include "boards/common/app_hooks.h"
#include "ports/stm32f1/stm32f1_regs.h"
#include "ports/stm32_common/systick_clock.h"
#include "ports/stm32f1/stm32f1_bus.h"
#include "ports/stm32f1/stm32f1_uart.h"
#include "ports/stm32f1/usart_hd.h"

/* The config store's pages, kept in RAM at the addresses they would have. */
#define FLASH_PAGE ((uint32_t)BOARD_FLASH_PAGE)
#define RAM_FLASH_BASE ((uint32_t)BOARD_RAM_CONFIG_BASE)

static struct servo servo;
static struct usart_hd usart;
static uint8_t rx_bytes[BOARD_RX_RING_BYTES];
static struct hal_rx_ring rx_ring = HAL_RX_RING_OVER(rx_bytes);
static struct plant_fixed plant;
static uint8_t flash_mem[2 * FLASH_PAGE];
static struct hal_flash flash;

static void motor_drive(void *ctx, int16_t duty)
{
    (void)ctx;
    plant.duty = duty;
    plant.coast = false;
}

static void motor_coast(void *ctx)
{
    (void)ctx;
    plant.coast = true;
}

/* Read once per control tick: the model advances one tick. */
static uint16_t encoder_read(void *ctx)
{
    (void)ctx;
    plant_fixed_step(&plant);
    return plant_fixed_encoder(&plant);
}

static void sensors_read(void *ctx, struct sensor_raw *out)
{
    (void)ctx;
    out->supply = (uint16_t)(7400u * 1000u / BOARD_SUPPLY_UV_PER_COUNT);
    out->current = (uint16_t)(plant_fixed_current_ma(&plant) * 1000u / BOARD_CURRENT_UA_PER_COUNT);
    out->ntc = 2048; /* 25 degC */
}

static const struct sensor_calibration calibration = BOARD_SENSOR_CALIBRATION;

static bool ram_erase(void *ctx, uint32_t addr)
{
    (void)ctx;
    uint32_t offset = addr - RAM_FLASH_BASE;
    for (uint32_t i = 0; i < FLASH_PAGE; i++) {
        flash_mem[offset + i] = 0xFF;
    }
    return true;
}

static bool ram_program(void *ctx, uint32_t addr, const uint8_t *data)
{
    (void)ctx;
    uint32_t offset = addr - RAM_FLASH_BASE;
    flash_mem[offset] &= data[0];
    flash_mem[offset + 1u] &= data[1];
    return true;
}

static void ram_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    for (uint32_t i = 0; i < len; i++) {
        dst[i] = flash_mem[addr - RAM_FLASH_BASE + i];
    }
}

STM32F1_BUS_DEFINED

/* QEMU's part has no unique ID: a fixed serial number. */
static uint32_t serial_number(void *ctx)
{
    (void)ctx;
    return 0x0E3A0001u;
}

/* The board's wiring: which driver or model does what, in one place. */
static const struct hal_port port = {
    .ctx = &usart,
    .bus = PORT_UART_BUS_INTERRUPT,
    .rx = &rx_ring,
    .motor = {.drive = motor_drive, .coast = motor_coast, .read_encoder = encoder_read,
              .read_sensors = sensors_read},
    .calibration = &calibration,
    .flash = &flash,
    .serial_number = serial_number,
    .rx_gap_tolerance_us = QEMU_RX_GAP_TOLERANCE_US,
    APP_HOOKS_PORT_FIELDS,
};

int main(void)
{
    for (uint32_t i = 0; i < sizeof flash_mem; i++) {
        flash_mem[i] = 0xFF;
    }
    flash = hal_flash_two_pages(NULL, FLASH_PAGE, RAM_FLASH_BASE, ram_erase, ram_program, ram_read);
    systick_clock_init(QEMU_CORE_HZ);
    port_uart_init(&usart, &rx_ring, NULL, QEMU_CORE_HZ, &bus_hw); /* no DMA model: by interrupt */
    usart_hd_tx_polled(&usart); /* QEMU 7.2's USART raises no transmit interrupts */
    usart_hd_no_echo(&usart);   /* and its socket does not echo our bytes */
    servo_init(&servo, &port);
    NVIC_ISER(BUS_USART_IRQ / 32u) = 1u << (BUS_USART_IRQ % 32u);
    for (;;) {
        usart_hd_service(&usart);
        servo_poll(&servo);
    }
}
