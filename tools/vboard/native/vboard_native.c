/* What the virtual boards (tools/vboard) take from the host build, for
 * Python through ctypes: the simulator's motor and winding models
 * (hal/ports/host/plant.c, thermal.c), so a virtual board's motor is the
 * simulator's, and the config store's own code, which writes the factory
 * record of a board's ID into its config page as servo_sim does for a blank
 * chip. Built without sanitizers: Python loads it. */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "storage/config_peek.h"
#include "storage/config_store.h"
#include "ports/host/plant_model.h"
#include "registers/data_table.h"
#include "ports/host/thermal.h"

struct vboard_motor {
    struct plant plant;
    struct thermal thermal;
};

uint32_t vboard_motor_size(void);
void vboard_motor_init(struct vboard_motor *m, double supply_v, double ambient_c);
int vboard_motor_load_plant(struct vboard_motor *m, const char *path, double ambient_c, char *err,
                            uint32_t err_size);
void vboard_motor_step(struct vboard_motor *m, double dt);
void vboard_motor_drive(struct vboard_motor *m, double duty);
void vboard_motor_coast(struct vboard_motor *m);
uint16_t vboard_motor_encoder(const struct vboard_motor *m);
double vboard_motor_get(const struct vboard_motor *m, int what);
void vboard_motor_set(struct vboard_motor *m, int what, double value);
unsigned vboard_motor_ntc_adc(const struct vboard_motor *m);
int vboard_factory_config(uint8_t *pages, uint32_t page_size, uint32_t page0_addr, uint8_t id);
int vboard_stored_id(uint8_t *pages, uint32_t page_size, uint32_t page0_addr);

enum { ANGLE_DEG, VELOCITY_DPS, CURRENT_A, SUPPLY_V, LOAD_NM, WINDING_C, CASE_C, AMBIENT_C, STOP_DEG,
       SOAK_C, PAYLOAD_GCM2 };

uint32_t vboard_motor_size(void)
{
    return (uint32_t)sizeof(struct vboard_motor);
}

void vboard_motor_init(struct vboard_motor *m, double supply_v, double ambient_c)
{
    plant_init(&m->plant);
    m->plant.p.supply_v = supply_v;
    thermal_init(&m->thermal, ambient_c);
}

/* A plant file's motor (plant_model.h), at the file's supply: 1, or 0 with
 * the reason in err and the motor as it was. */
int vboard_motor_load_plant(struct vboard_motor *m, const char *path, double ambient_c, char *err,
                            uint32_t err_size)
{
    struct plant_model model;
    if (!plant_model_load(path, &model, err, err_size)) {
        return 0;
    }
    plant_model_apply(&model, &m->plant, &m->thermal, ambient_c);
    return 1;
}

/* The winding heats by I^2 R, as in servo_sim. */
void vboard_motor_step(struct vboard_motor *m, double dt)
{
    plant_step(&m->plant, dt);
    double i = m->plant.current;
    thermal_step(&m->thermal, i * i * m->plant.p.resistance_ohm, dt);
}

void vboard_motor_drive(struct vboard_motor *m, double duty)
{
    double q15 = duty * 32767.0;
    plant_drive(&m->plant, (int16_t)(q15 > 32767.0 ? 32767 : q15 < -32767.0 ? -32767 : q15));
}

void vboard_motor_coast(struct vboard_motor *m)
{
    plant_coast(&m->plant);
}

uint16_t vboard_motor_encoder(const struct vboard_motor *m)
{
    return plant_encoder(&m->plant);
}

double vboard_motor_get(const struct vboard_motor *m, int what)
{
    switch (what) {
    case ANGLE_DEG: return plant_angle_deg(&m->plant);
    case VELOCITY_DPS: return m->plant.velocity * 180.0 / 3.14159265358979323846;
    case CURRENT_A: return m->plant.current;
    case SUPPLY_V: return m->plant.p.supply_v;
    case LOAD_NM: return m->plant.load_torque;
    case PAYLOAD_GCM2: return m->plant.payload_inertia * 1e7;
    case WINDING_C: return m->thermal.winding_c;
    case CASE_C: return m->thermal.case_c;
    case AMBIENT_C: return m->thermal.ambient_c;
    case STOP_DEG: return m->plant.has_stop ? m->plant.stop_angle * 180.0 / 3.14159265358979323846 : 1e9;
    default: return 0.0;
    }
}

void vboard_motor_set(struct vboard_motor *m, int what, double value)
{
    switch (what) {
    case SUPPLY_V: m->plant.p.supply_v = value; break;
    case LOAD_NM: m->plant.load_torque = value; break;
    case PAYLOAD_GCM2: m->plant.payload_inertia = value * 1e-7; break; /* g cm^2 to kg m^2 */
    case AMBIENT_C: m->thermal.ambient_c = value; break;
    case SOAK_C: thermal_soak(&m->thermal, value); break;
    case STOP_DEG:
        m->plant.has_stop = value < 1e8;
        m->plant.stop_angle = value * 3.14159265358979323846 / 180.0;
        break;
    default: break;
    }
}

unsigned vboard_motor_ntc_adc(const struct vboard_motor *m)
{
    return thermal_ntc_adc(&m->thermal);
}

/* A RAM flash with the STM32F1's rules, for the factory record. */
struct ram_flash {
    uint8_t *mem;
    uint32_t base;
    uint32_t size;
};

static bool ram_erase(void *ctx, uint32_t addr)
{
    struct ram_flash *f = ctx;
    memset(&f->mem[addr - f->base], 0xFF, f->size / 2u);
    return true;
}

static bool ram_program(void *ctx, uint32_t addr, const uint8_t *data)
{
    struct ram_flash *f = ctx;
    memcpy(&f->mem[addr - f->base], data, 2);
    return true;
}

static void ram_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    struct ram_flash *f = ctx;
    memcpy(dst, &f->mem[addr - f->base], len);
}

static struct hal_flash ram_flash_of(struct ram_flash *ram, uint32_t page_size, uint32_t page0_addr)
{
    return hal_flash_two_pages(ram, page_size, page0_addr, ram_erase, ram_program, ram_read);
}

/* pages: the two config pages, erased, page0_addr first: the record of the
 * factory user area with servo ID id. 1 when the store holds it: written,
 * or, for the factory defaults' own ID (0), a blank store, which the
 * firmware reads as its factory defaults. */
int vboard_factory_config(uint8_t *pages, uint32_t page_size, uint32_t page0_addr, uint8_t id)
{
    struct ram_flash ram = {pages, page0_addr, 2u * page_size};
    const struct hal_flash flash = ram_flash_of(&ram, page_size, page0_addr);
    struct config_store store;
    struct user_config cfg;
    (void)config_store_load(&store, &flash, &cfg);
    cfg.servo_id = id;
    return config_store_save(&store, &cfg, 0) != CONFIG_WRITE_FAILED;
}

/* The ID a board's store holds, as its bootloader reads it (config_peek):
 * the ID the board answers at. */
int vboard_stored_id(uint8_t *pages, uint32_t page_size, uint32_t page0_addr)
{
    struct ram_flash ram = {pages, page0_addr, 2u * page_size};
    const struct hal_flash flash = ram_flash_of(&ram, page_size, page0_addr);
    uint8_t id = 0;
    uint8_t baud_index = 0;
    config_peek_link(&flash, &id, &baud_index);
    return id;
}
