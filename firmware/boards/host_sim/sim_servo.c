#define _POSIX_C_SOURCE 200809L
#include "sim_servo.h"

#include <math.h>
#include <stdio.h>
#include <time.h>

#include "calibration.h"
#include "config_store.h"
#include "protocol/data_table.h"
#include "sim_bus.h"

uint64_t sim_now_us(void)
{
    static uint64_t start;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    uint64_t us = (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
    if (start == 0) {
        start = us - 1000u; /* never 0 */
    }
    return us - start;
}

/* Runs motor and winding up to now with the drive last set; the bus clock
 * moves in small steps, so dt stays near one control tick. */
static void run_models(struct sim_servo *s)
{
    uint64_t now = s->bus->now_us;
    double dt = (double)(now - s->stepped_us) * 1e-6;
    s->stepped_us = now;
    if (dt <= 0) {
        return;
    }
    plant_step(&s->plant, dt);
    double i = s->plant.current;
    thermal_step(&s->thermal, i * i * s->plant.p.resistance_ohm, dt);
}

/* The firmware's clock is the bus's (see sim_bus.h). */
static uint32_t now_us(void *ctx)
{
    const struct sim_servo *s = ctx;
    return (uint32_t)s->bus->now_us;
}

static void uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    struct sim_servo *s = ctx;
    s->tx_done_us = sim_bus_send(s->bus, s->index, data, len, s->baud, s->bus->now_us);
}

static bool uart_tx_done(void *ctx)
{
    const struct sim_servo *s = ctx;
    return s->bus->now_us >= s->tx_done_us;
}

static void uart_set_baud(void *ctx, uint32_t baud)
{
    ((struct sim_servo *)ctx)->baud = baud;
}

static void motor_drive(void *ctx, int16_t duty)
{
    struct sim_servo *s = ctx;
    run_models(s);
    plant_drive(&s->plant, duty);
}

static void motor_coast(void *ctx)
{
    struct sim_servo *s = ctx;
    run_models(s);
    plant_coast(&s->plant);
}

static uint16_t encoder_read(void *ctx)
{
    struct sim_servo *s = ctx;
    run_models(s);
    return plant_encoder(&s->plant);
}

static uint16_t counts(double value, double per_count)
{
    double c = floor(value / per_count + 0.5);
    return (uint16_t)(c < 0 ? 0 : c > 4095 ? 4095 : c);
}

/* The reference board's ADC readings of the models' supply, shunt current
 * and NTC. */
static void sensors_read(void *ctx, struct sensor_raw *out)
{
    struct sim_servo *s = ctx;
    out->supply = counts(s->plant.p.supply_v * 1e6, BOARD_SUPPLY_UV_PER_COUNT);
    out->current = (uint16_t)(counts(fabs(s->plant.current) * 1e6, BOARD_CURRENT_UA_PER_COUNT) +
                              BOARD_CURRENT_ZERO_COUNTS);
    out->ntc = (uint16_t)thermal_ntc_adc(&s->thermal);
}

static const struct sensor_calibration calibration = BOARD_SENSOR_CALIBRATION;

/* A blank chip gets the ID it was started with, as at the factory. */
static bool program_id(struct sim_flash *flash, uint8_t id)
{
    struct config_store store;
    struct user_config cfg;
    if (config_store_load(&store, &flash->hal, &cfg)) {
        return true;
    }
    cfg.servo_id = id;
    return config_store_save(&store, &cfg, 0) != CONFIG_WRITE_FAILED;
}

bool sim_servo_start(struct sim_servo *s, struct sim_bus *bus, unsigned index, uint8_t id,
                     const char *state_dir, double supply_v, double ambient_c)
{
    char path[300];
    snprintf(path, sizeof path, "%s/servo-%u.flash", state_dir, id);
    if (!sim_flash_open(&s->flash, path)) {
        fprintf(stderr, "servo_sim: cannot open the flash file %s: ", path);
        perror(NULL);
        return false;
    }
    if (!program_id(&s->flash, id)) {
        fprintf(stderr, "servo_sim: cannot write the flash file %s\n", path);
        return false;
    }
    s->bus = bus;
    s->index = index;
    s->cmdline_id = id;
    plant_init(&s->plant);
    s->plant.p.supply_v = supply_v;
    thermal_init(&s->thermal, ambient_c);
    s->stepped_us = bus->now_us;
    s->port = (struct hal_port){
        .ctx = s,
        .now_us = now_us,
        .uart_send = uart_send,
        .uart_tx_done = uart_tx_done,
        .uart_set_baud = uart_set_baud,
        .rx = &s->rx,
        .motor_drive = motor_drive,
        .motor_coast = motor_coast,
        .encoder_read = encoder_read,
        .sensors_read = sensors_read,
        .calibration = &calibration,
        .flash = &s->flash.hal,
        .serial_number = 0x51A00000u | id,
    };
    servo_init(&s->core, &s->port);
    s->flash.stall_us = 0; /* power-up, before the servo joins the bus */
    return true;
}

void sim_servo_receive(struct sim_servo *s, uint8_t byte, uint64_t at_us)
{
    if (s->rx_interrupt) {
        if (at_us < s->cpu_free_us) {
            if (s->uart_full) {
                s->rx.overruns++; /* the receive interrupt could not run */
            } else {
                s->uart_full = true;
                s->uart_held = byte;
                s->uart_held_at_us = (uint32_t)at_us;
            }
            return;
        }
        if (s->uart_full) {
            s->uart_full = false;
            hal_rx_ring_put(&s->rx, s->uart_held, s->uart_held_at_us);
        }
    }
    servo_on_rx_byte(&s->core, byte, (uint32_t)at_us);
}

void sim_servo_poll(struct sim_servo *s, uint64_t now_us)
{
    if (now_us < s->cpu_free_us) {
        return;
    }
    if (s->uart_full) { /* the interrupt runs as soon as the CPU does */
        s->uart_full = false;
        hal_rx_ring_put(&s->rx, s->uart_held, s->uart_held_at_us);
    }
    servo_poll(&s->core);
    if (s->flash.stall_us != 0u) {
        s->cpu_free_us = now_us + s->flash.stall_us;
        s->flash_stall_us += s->flash.stall_us;
        s->flash.stall_us = 0;
    }
}
