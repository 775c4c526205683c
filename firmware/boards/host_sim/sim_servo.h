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
    /* The CPU, stalled by the flash until cpu_free_us (sim_flash.h): no
     * main loop, no tick, no interrupt. With rx_interrupt the port takes
     * each byte in its receive interrupt, so the USART holds one byte
     * (uart_held) and loses the next ones; by DMA (the reference board)
     * bytes go on into the ring. */
    uint64_t cpu_free_us;
    bool rx_interrupt;
    bool uart_full;
    uint8_t uart_held;
    uint32_t uart_held_at_us;
    uint64_t flash_stall_us; /* in all */
};

/* Monotonic microseconds since the simulator started. */
uint64_t sim_now_us(void);

/* Opens the servo's flash file in state_dir (giving a blank chip the ID
 * `id`) and starts its core. False, with a message, on failure. */
bool sim_servo_start(struct sim_servo *s, struct sim_bus *bus, unsigned index, uint8_t id,
                     const char *state_dir, double supply_v, double ambient_c);

/* A byte off the wire at at_us, as the port takes it. */
void sim_servo_receive(struct sim_servo *s, uint8_t byte, uint64_t at_us);

/* A main-loop pass, unless the flash stalls the CPU at now_us; the stall
 * of what it did to the flash starts at now_us. */
void sim_servo_poll(struct sim_servo *s, uint64_t now_us);

#endif
