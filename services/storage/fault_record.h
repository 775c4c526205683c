/* The fault history's entries (ReadFaults, 0x43): what tripped, when, and
 * the readings at that moment. The log in flash: storage/fault_log.h. */
#ifndef STORAGE_FAULT_RECORD_H
#define STORAGE_FAULT_RECORD_H

#include <stdint.h>

/* What tripped: status bits 2-7 by their number, the watchdog, the
 * oscillation monitor; then the resets the servo did not plan, by the
 * kind the board read at start-up (hal/hal_reset.h gives them the same
 * numbers). */
enum fault_kind {
    FAULT_CLEARED = 0, /* a ClearFaults marker: older faults are not shown */
    FAULT_STALL = 2,
    FAULT_HIGH_VOLTAGE = 3,
    FAULT_LOW_VOLTAGE = 4,
    FAULT_OVER_CURRENT = 5,
    FAULT_OVER_POWER = 6,
    FAULT_OVER_TEMPERATURE = 7,
    FAULT_WATCHDOG = 8,
    FAULT_OSCILLATION = 9, /* the oscillation monitor (item 72) released it */
    FAULT_FIRMWARE = 10,   /* its own code faulted: the entry's `code` */
    FAULT_RESET_WATCHDOG = 11, /* the independent watchdog: the main loop hung */
    FAULT_RESET_SOFTWARE = 12, /* a software reset the firmware did not plan */
    FAULT_BROWN_OUT = 13,      /* the supply fell below the reset level */
    FAULT_RESET_PIN = 14,      /* the reset pin, from outside */
    FAULT_RESET_LOW_POWER = 15,
};

/* A firmware fault's record, in place of the readings (FAULT_FIRMWARE). */
struct __attribute__((packed, aligned(2))) fault_code {
    uint32_t pc;            /* the faulting instruction (the exception's stacked PC) */
    uint32_t lr;
    uint16_t sp_offset;     /* the stack pointer less the RAM's base */
    uint16_t mm_bus_status; /* ARMv7-M CFSR bits 0-15 (MemManage, BusFault); 0 on ARMv6-M */
    uint8_t exception;      /* the exception taken: 3 HardFault, 4 MemManage, 5 BusFault,
                             * 6 UsageFault, 16 on an interrupt; 0 the M0's stack guard */
    uint8_t usage_status;   /* CFSR bits 16-19 and 24-25 in bits 0-5, HFSR VECTTBL bit 6,
                             * FORCED bit 7 */
};


/* The faults ReadFaults shows, newest first. */
#define FAULT_HISTORY 16u

/* Laid out as its bytes in the log's record and in ReadFaults' answer
 * (little-endian, no padding before `what`): each is a copy of it. */
struct fault_entry {
    uint32_t number;        /* since the log was blank, from 1: faults and clears */
    uint32_t op_seconds;    /* operating time (as ReadStore's) */
    union {
        /* The readings at that moment (every kind but FAULT_FIRMWARE). */
        struct __attribute__((packed, aligned(2))) {
            int32_t angle_decideg;  /* multi-turn */
            uint16_t voltage_mv;
            uint16_t current_ma;
            uint16_t power_mw;
            int16_t winding_decic;  /* item 68 */
            int16_t case_decic;     /* the NTC's reading in 0.1 degC */
        };
        struct fault_code code;
    };
    uint8_t what;           /* enum fault_kind */
};
_Static_assert(sizeof(struct fault_code) == 14u, "a fault's code takes the readings' 14 bytes");
/* The bytes that are the entry: up to and with `what`. */
#define FAULT_ENTRY_BYTES 23u

#endif
