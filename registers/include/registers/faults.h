/* The fault history's entries (ReadFaults, 0x43): what tripped, when, and
 * the readings at that moment. The log in flash: storage/fault_log.h. */
#ifndef REGISTERS_FAULTS_H
#define REGISTERS_FAULTS_H

#include <stdint.h>

/* What tripped: status bits 2-7 by their number, the watchdog and the
 * oscillation monitor. */
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
};

/* The faults ReadFaults shows, newest first. */
#define FAULT_HISTORY 16u

/* Laid out as its bytes in the log's record and in ReadFaults' answer
 * (little-endian, no padding before `what`): each is a copy of it. */
struct fault_entry {
    uint32_t number;        /* since the log was blank, from 1: faults and clears */
    uint32_t op_seconds;    /* operating time (as ReadStore's) */
    int32_t angle_decideg;  /* multi-turn */
    uint16_t voltage_mv;
    uint16_t current_ma;
    uint16_t power_mw;
    int16_t winding_decic;  /* item 68 */
    int16_t case_decic;     /* the NTC's reading in 0.1 degC */
    uint8_t what;           /* enum fault_kind */
};
/* The bytes that are the entry: up to and with `what`. */
#define FAULT_ENTRY_BYTES 23u

#endif
