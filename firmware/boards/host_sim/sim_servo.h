/* One simulated servo: the firmware core on a host HAL port whose motor,
 * encoder, sensors and flash come from models. */
#ifndef SIM_SERVO_H
#define SIM_SERVO_H

#include <stdint.h>

#include "plant.h"
#include "servo.h"
#include "sim_flash.h"
#include "thermal.h"

struct sim_bus;

struct sim_servo {
    struct servo core;
    struct hal_port port;
    struct plant plant;
    struct thermal thermal;
    struct sim_flash flash;
    struct hal_rx_ring rx;
    struct sim_bus *bus;
    unsigned index;       /* on the bus */
    uint8_t cmdline_id;   /* the ID it was started with (names its flash file) */
    uint32_t baud;
    uint64_t tx_done_us;
    uint64_t stepped_us;  /* the models have run up to here */
};

/* Monotonic microseconds since the simulator started. */
uint64_t sim_now_us(void);

/* Opens the servo's flash file in state_dir (giving a blank chip the ID
 * `id`) and starts its core. False, with a message, on failure. */
bool sim_servo_start(struct sim_servo *s, struct sim_bus *bus, unsigned index, uint8_t id,
                     const char *state_dir, double supply_v, double ambient_c);

#endif
