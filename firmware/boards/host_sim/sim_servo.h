/* One simulated servo: the firmware core on a host HAL port whose motor,
 * encoder, sensors and flash come from models. */
#ifndef SIM_SERVO_H
#define SIM_SERVO_H

#include <stdint.h>

#include "bootloader/app_image.h"
#include "board.h"
#include "bootloader/bootloader.h"
#include "ports/host/plant_model.h"
#include "app/servo.h"
#include "sim_bus.h"
#include "sim_cpu.h"
#include "ports/host/sim_flash.h"
#include "ports/host/thermal.h"

/* The simulated servo's flash map and board ID (board.h), in C's types. */
#define SIM_SLOT_BASE ((uint32_t)BOARD_SLOT_BASE)
#define SIM_SLOT_PAGES ((uint32_t)BOARD_SLOT_PAGES)
#define SIM_CONFIG_BASE ((uint32_t)BOARD_CONFIG_PAGE0)
#define SIM_BOARD ((uint16_t)BOARD_ID)
/* The bootloader, as the simulator runs it (sim_servo.c): the boards' loop
 * (bootloader.c) on the servo's port; the image in the slot is not
 * executed, its version is what the "application" then reports (data
 * item 7). */
struct sim_boot {
    struct boot_board board;
    struct boot_loop loop;
};


struct sim_servo {
    struct servo core;
    /* How the board is built (control port: magnet, swapleads, ampzero):
     * the encoder's count at the output's zero, the motor's leads swapped,
     * the current amplifier's ADC count at no current. */
    uint16_t magnet_counts;
    bool leads_swapped;
    uint16_t amp_zero_counts;
    struct hal_port port;
    struct plant plant;
    struct thermal thermal;
    struct sim_flash flash;      /* the config store's pages */
    struct sim_flash slot_flash; /* the application slot */
    struct sim_flash fault_flash; /* the fault history's pages */
    struct app_slot slot;
    uint8_t config_mem[2u * SIM_FLASH_PAGE];
    uint8_t fault_mem[2u * SIM_FLASH_PAGE];
    uint8_t slot_mem[SIM_SLOT_PAGES * SIM_FLASH_PAGE];
    bool in_bootloader;
    struct sim_boot boot;
    struct hal_rx_ring rx;
    uint8_t rx_bytes[BOARD_RX_RING_BYTES];
    struct sim_bus *bus;
    unsigned index;       /* on the bus */
    uint8_t cmdline_id;   /* the ID it was started with */
    uint8_t unit;         /* servos started before it with the same ID */
    unsigned power_ups;   /* the first, then one a power cycle */
    uint32_t baud;
    uint64_t tx_done_us;
    uint64_t stepped_us;  /* the models have run up to here */
    /* The CPU, stalled by the flash until cpu_free_us (sim_flash.h): no
     * main loop, no tick, no interrupt. With rx_interrupt the port takes
     * each byte in its receive interrupt, so the USART holds one byte
     * (uart_held) and loses the next ones; by DMA (the reference board)
     * bytes go on into the ring. */
    uint64_t cpu_free_us;
    /* The main loop as the target's CPU runs it (sim_cpu.h): the next pass
     * starts when this one would have ended, or, asleep, at the interrupt
     * that wakes it (the tick, the USART's IDLE, a byte's interrupt, a
     * transmission's end). The bytes of an answer wait in tx_data for the
     * end of the pass that sent them. */
    const struct sim_cpu *cpu;
    uint64_t next_pass_us;
    uint64_t idle_at_us; /* the line's IDLE after the last byte; 0: none due */
    bool asleep;
    /* Awake while the line is in use, with nothing to do but frame bytes
     * as they land (servo_awaits_bytes): the next pass runs half a pass
     * after the next byte lands (landed_us), unless an interrupt's comes
     * first. */
    bool polling;
    uint64_t landed_us; /* 0: none since the last pass */
    const uint8_t *tx_data;
    uint16_t tx_len;
    bool rx_interrupt;
    bool uart_full;
    uint8_t uart_held;
    uint32_t uart_held_at_us;
    uint64_t flash_stall_us; /* in all */
    /* Status bit 0 as the simulator's clock saw it: when the current
     * execution began, and how long the last one lasted (tests judge moves
     * in simulated time, not the host's). */
    bool executing;
    uint64_t executing_from_us;
    uint64_t last_execution_us;
    uint64_t last_sent_us;   /* its last frame started onto the wire */
    /* For the bus watchdog's tests: when a frame for this servo was last
     * carried out, and when a driven output was last let go. */
    uint64_t heard_us;
    uint32_t heard_seen;
    uint64_t coasted_us;
    bool driven;
};

/* Monotonic microseconds since the simulator started, plus every skip. */
uint64_t sim_now_us(void);
/* Moves sim_now_us() on by us at once (sim_clock.h: a host that waits). */
void sim_skip_us(uint64_t us);

/* Opens the servo's flash files in state_dir (giving a blank chip the ID
 * `id`) and starts its core. unit counts the servos started before it with
 * the same ID: it names its files and its serial number apart from theirs.
 * False, with a message, on failure. */
bool sim_servo_start(struct sim_servo *s, struct sim_bus *bus, unsigned index, uint8_t id,
                     uint8_t unit, const char *state_dir, const struct plant_model *plant,
                     double supply_v, double ambient_c);

/* Data item 8 of this servo: 0x51A0UUNN (UU its unit, NN the ID it was
 * started with), the same at every start. */
uint32_t sim_servo_serial(const struct sim_servo *s);

/* The ID the servo answers at now: its application's, or its
 * bootloader's (the stored one). */
uint8_t sim_servo_bus_id(const struct sim_servo *s);

/* A byte off the wire at at_us, as the port takes it. */
/* The servo as a station of the bus: its UART. */
struct sim_station sim_servo_station(struct sim_servo *s);

/* When the servo's CPU next runs a main-loop pass (sim_servo_poll does
 * nothing before): the end of its last pass or of a flash stall, or, when
 * it sleeps, the interrupt that wakes it. */
uint64_t sim_servo_wake_at(const struct sim_servo *s);

/* A main-loop pass, if one is due at now_us (sim_servo_wake_at); the stall
 * of what it did to the flash starts at now_us. */
void sim_servo_poll(struct sim_servo *s, uint64_t now_us);

/* A main-loop pass of the bootloader (sim_servo.c): false once it has
 * started the application. */
bool sim_servo_boot_poll(struct sim_servo *s);

/* The power goes and comes back: the servo restarts through its
 * bootloader (200 ms listening, or for good without a valid image). */
void sim_servo_power_cycle(struct sim_servo *s);

#endif
