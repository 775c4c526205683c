#define _POSIX_C_SOURCE 200809L
#include "sim_servo.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "storage/config_peek.h"
#include "storage/config_store.h"
#include "runtime/crc32.h"
#include "registers/data_table.h"
#include "sim_bus.h"
#include "bootloader/slot_write.h"

static uint64_t skipped_us;

void sim_skip_us(uint64_t us)
{
    skipped_us += us;
}

uint64_t sim_now_us(void)
{
    static uint64_t start;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    uint64_t us = (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
    if (start == 0) {
        start = us - 1000u; /* never 0 */
    }
    return us - start + skipped_us;
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

/* The UART starts once the pass that handed it the bytes has run on the
 * target's CPU (sim_servo_poll): until then it is not done. */
static void uart_send(void *ctx, const uint8_t *data, uint16_t len)
{
    struct sim_servo *s = ctx;
    s->tx_data = data;
    s->tx_len = len;
    s->tx_done_us = UINT64_MAX;
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
    plant_drive(&s->plant, s->leads_swapped ? (int16_t)-duty : duty);
    s->driven = true;
}

static void motor_coast(void *ctx)
{
    struct sim_servo *s = ctx;
    run_models(s);
    plant_coast(&s->plant);
    if (s->driven) {
        s->driven = false;
        s->coasted_us = s->bus->now_us;
    }
}

static uint16_t encoder_read(void *ctx)
{
    struct sim_servo *s = ctx;
    run_models(s);
    return (uint16_t)((plant_encoder(&s->plant) + s->magnet_counts) & 4095u);
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
    unsigned current = counts(fabs(s->plant.current) * 1e6, BOARD_CURRENT_UA_PER_COUNT) + BOARD_CURRENT_ZERO_COUNTS +
                       s->amp_zero_counts;
    out->current = (uint16_t)(current > 4095u ? 4095u : current);
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

/* A blank chip's slot gets the factory's image: a header for this
 * firmware's version and 4 KB of stand-in code (the simulator runs the
 * servo core, not the image). */
static bool program_factory_image(struct sim_servo *s, uint16_t version)
{
    enum { CODE = 4096 };
    static uint8_t image[APP_HEADER_SIZE + CODE];
    for (uint32_t i = 0; i < CODE; i++) {
        image[APP_HEADER_SIZE + i] = (uint8_t)(i * 13u + 7u);
    }
    app_image_make_header(image, &image[APP_HEADER_SIZE], CODE, version, SIM_BOARD);
    for (uint32_t page = 0; page < (sizeof image + SIM_FLASH_PAGE - 1u) / SIM_FLASH_PAGE; page++) {
        if (slot_erase_page(&s->slot, page) != SLOT_WRITE_OK) {
            return false;
        }
    }
    return slot_write(&s->slot, 0, image, sizeof image, crc32(image, sizeof image)) == SLOT_WRITE_OK;
}

uint32_t sim_servo_serial(const struct sim_servo *s)
{
    return 0x51A00000u | (uint32_t)s->unit << 8 | s->cmdline_id;
}

uint8_t sim_servo_bus_id(const struct sim_servo *s)
{
    return s->in_bootloader ? s->boot.loop.id : s->core.active_id;
}

static uint32_t serial_number(void *ctx)
{
    return sim_servo_serial(ctx);
}

/* The image "running": its header's version, as on a board. */
static uint16_t image_version(void *ctx)
{
    struct sim_servo *s = ctx;
    struct app_image_info info;
    return app_image_check(&s->slot, SIM_BOARD, &info) == APP_IMAGE_VALID ? info.version : 0u;
}

/* The application starts: the servo core, reporting the slot image's
 * version. */
static void start_app(struct sim_servo *s)
{
    s->in_bootloader = false;
    servo_init(&s->core, &s->port);
}

/* The bootloader, the boards' loop (bootloader/bootloader.c) on the
 * servo's port: its receive ring and UART, the config store's flash file,
 * the slot's. A reset into it (stay: UpdateEnter asked), and its main-loop
 * pass: false once it has started the application. */
static void boot_reset(struct sim_servo *s, bool stay, uint8_t link_id, uint8_t link_baud)
{
    struct sim_boot *b = &s->boot;
    if (!stay) { /* a power-up: the store's newest record */
        config_peek_link(s->port.flash, &link_id, &link_baud);
    }
    b->board = (struct boot_board){.port = &s->port, .slot = &s->slot, .board = SIM_BOARD,
                                   .stay_word = stay ? BOOT_STAY_MAGIC : 0u,
                                   .link_id = link_id, .link_baud = link_baud};
    s->rx.read = s->rx.written; /* what the application had not read is gone */
    boot_loop_start(&b->loop, &b->board);
    run_models(s);
    plant_coast(&s->plant); /* a reset lets go of the output */
    s->in_bootloader = true;
}

bool sim_servo_boot_poll(struct sim_servo *s)
{
    run_models(s);
    if (boot_loop_step(&s->boot.loop)) {
        return true;
    }
    start_app(s);
    return false;
}

static void enter_bootloader(void *ctx, uint8_t id, uint8_t baud_index)
{
    boot_reset(ctx, true, id, baud_index); /* where the application answered */
}

void sim_servo_power_cycle(struct sim_servo *s)
{
    s->power_ups++;
    boot_reset(s, false, 0, 0);
}

bool sim_servo_start(struct sim_servo *s, struct sim_bus *bus, unsigned index, uint8_t id,
                     uint8_t unit, const char *state_dir, const struct plant_model *plant,
                     double supply_v, double ambient_c)
{
    /* servo-ID.flash; the second servo given that ID servo-ID-2.flash. */
    char name[32];
    if (unit == 0u) {
        snprintf(name, sizeof name, "servo-%u", id);
    } else {
        snprintf(name, sizeof name, "servo-%u-%u", id, unit + 1u);
    }
    char path[300];
    snprintf(path, sizeof path, "%s/%s.flash", state_dir, name);
    char slot_path[300];
    snprintf(slot_path, sizeof slot_path, "%s/%s.slot", state_dir, name);
    char fault_path[300];
    snprintf(fault_path, sizeof fault_path, "%s/%s.faults", state_dir, name);
    if (!sim_flash_open(&s->flash, path, SIM_CONFIG_BASE, 2, s->config_mem) ||
        !sim_flash_open(&s->slot_flash, slot_path, SIM_SLOT_BASE, SIM_SLOT_PAGES, s->slot_mem) ||
        !sim_flash_open(&s->fault_flash, fault_path, BOARD_FAULT_PAGE0, 2, s->fault_mem)) {
        fprintf(stderr, "servo_sim: cannot open the flash files %s, %s, %s: ", path, slot_path,
                fault_path);
        perror(NULL);
        return false;
    }
    s->slot = (struct app_slot){.flash = &s->slot_flash.hal, .base = SIM_SLOT_BASE,
                                .pages = SIM_SLOT_PAGES};
    if (!program_id(&s->flash, id)) {
        fprintf(stderr, "servo_sim: cannot write the flash file %s\n", path);
        return false;
    }
    s->bus = bus;
    s->index = index;
    s->cmdline_id = id;
    s->unit = unit;
    s->power_ups = 1;
    s->rx = (struct hal_rx_ring)HAL_RX_RING_OVER(s->rx_bytes);
    plant_model_apply(plant, &s->plant, &s->thermal, ambient_c);
    s->plant.p.supply_v = supply_v;
    s->stepped_us = bus->now_us;
    s->port = (struct hal_port){
        HAL_PORT_HOST_FIELDS(s),
        .calibration = &calibration,
        .image_version = image_version,
        .enter_bootloader = enter_bootloader,
        .board = SIM_BOARD,
        .tick_and_pass_us = s->cpu->tick_and_pass_us,
    };
    /* Powered long before the host connects: the application runs (the
     * bootloader's listening window is modelled after a restart), if its
     * slot holds a valid image. Only a blank chip gets the factory image:
     * a slot an update left invalid stays so, and the servo waits in its
     * bootloader, as a real one would. */
    servo_init(&s->core, &s->port);
    if (s->slot_flash.created && !program_factory_image(s, s->core.regs.status.firmware_version)) {
        fprintf(stderr, "servo_sim: cannot write the slot file %s\n", slot_path);
        return false;
    }
    struct app_image_info info;
    if (app_image_check(&s->slot, SIM_BOARD, &info) == APP_IMAGE_VALID) {
        start_app(s);
    } else {
        boot_reset(s, false, 0, 0);
    }
    s->flash.stall_us = 0; /* power-up, before the servo joins the bus */
    s->slot_flash.stall_us = 0;
    s->fault_flash.stall_us = 0;
    return true;
}
