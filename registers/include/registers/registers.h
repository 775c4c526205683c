/* The register file: one struct per area of the data table
 * (servo-protocol.md 4.2), in protocol units. */
#ifndef REGISTERS_REGISTERS_H
#define REGISTERS_REGISTERS_H

#include <stdint.h>

/* Status area, data IDs 1-8: live readings and identity, read-only. */
struct status_area {
    uint16_t voltage_mv;       /* 1 */
    uint16_t current_ma;       /* 2 */
    uint16_t power_mw;         /* 3 */
    uint16_t temperature_adc;  /* 4: NTC ADC value, falls as it heats */
    uint8_t status;            /* 5: enum status_bit */
    uint16_t model;            /* 6 */
    uint16_t firmware_version; /* 7 */
    uint32_t serial_number;    /* 8 */
};

/* Bits of status (data ID 5). Bit 0 belongs to the motion layer, bit 1 to
 * the dispatcher, bits 2-7 to the protection monitors. */
enum status_bit {
    STATUS_EXECUTING = 1u << 0,
    STATUS_COMMAND_ERROR = 1u << 1,
    STATUS_STALL = 1u << 2,
    STATUS_HIGH_VOLTAGE = 1u << 3,
    STATUS_LOW_VOLTAGE = 1u << 4,
    STATUS_OVER_CURRENT = 1u << 5,
    STATUS_OVER_POWER = 1u << 6,
    STATUS_OVER_TEMPERATURE = 1u << 7,
};

/* User area, data IDs 32-53: configuration that persists. */
struct user_config {
    uint8_t check_flag;              /* 32: always 1 */
    uint8_t control_response;        /* 33: answer motion when finished */
    uint8_t servo_id;                /* 34 */
    uint8_t reserved_35;             /* 35: "control mode" in maker tables */
    uint8_t baud_index;              /* 36: enum in baud_rate_of_index() */
    uint8_t stall_release;           /* 37: 0 limit to 38, 1 release */
    uint16_t stall_power_mw;         /* 38 */
    uint16_t low_voltage_mv;         /* 39 */
    uint16_t high_voltage_mv;        /* 40 */
    uint16_t temperature_limit_adc;  /* 41: trips at or below */
    uint16_t power_limit_mw;         /* 42 */
    uint16_t current_limit_ma;       /* 43 */
    uint8_t start_force;             /* 44: "acceleration" */
    uint8_t reserved_45;             /* 45: "brake speed" in maker tables */
    uint8_t power_on_lock;           /* 46 */
    uint8_t wheel_brake;             /* 47 */
    uint8_t angle_limit_on;          /* 48 */
    uint8_t soft_start_on;           /* 49 */
    uint16_t soft_start_ms;          /* 50 */
    int16_t angle_max_decideg;       /* 51 */
    int16_t angle_min_decideg;       /* 52 */
    int16_t center_offset_decideg;   /* 53 */
};

/* How the config store is doing (ReadStore, 0x41, docs/packets.md): kept
 * up to date by the application, read by the dispatcher. */
enum store_flag {
    STORE_FAILED = 1u << 0,      /* the flash refused the last save or erase */
    STORE_OVER_BUDGET = 1u << 1, /* the last change was refused: wear budget */
    STORE_AWAITS_ERASE = 1u << 3, /* the last change was refused: no erased slot */
};

struct store_health {
    uint8_t flags;          /* enum store_flag */
    uint32_t records;       /* records written since the store was blank */
    uint32_t page_erases;   /* erases of the more worn page */
    uint32_t rated_cycles;  /* erases a page is rated for */
    uint32_t budget;        /* records the wear budget allows by now */
    uint32_t op_seconds;    /* operating time, as recorded with the saves */
    uint32_t failures;      /* failed saves since power-up */
    /* What flash work cost the bus since power-up (ReadStore): answers not
     * sent because their request arrived while an erase stalled the CPU
     * (they would have left outside their slot), and received bytes the
     * port's ring overwrote before the main loop took them. */
    uint32_t answers_dropped;
    uint32_t bytes_lost;
};

struct registers {
    struct status_area status;
    struct user_config user;
    struct store_health store;
};

/* Size of the user area on the wire (ReadBatchData/WriteBatchData) and in
 * the config store: every item at its own size, in ID order. */
#define USER_AREA_SIZE 32u

/* The link settings' ranges and factory baud rate (items 34 and 36), which
 * the bootloader checks without the data table. */
#define SERVO_ID_MAX 254u
#define BAUD_INDEX_MIN 1u
#define BAUD_INDEX_MAX 8u
#define BAUD_INDEX_FACTORY 5u

#endif
