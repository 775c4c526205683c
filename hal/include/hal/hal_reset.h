/* Why the MCU last started, as the board read it once at start-up (on the
 * STM32 boards: RCC_CSR's reset flags and the record kept in RAM across the
 * reset, boards/common/reset_cause.c), for the fault history. The kinds
 * that are faults carry the fault history's numbers (storage/fault_record.h). */
#ifndef HAL_RESET_H
#define HAL_RESET_H

#include <stdint.h>

enum hal_reset_kind {
    HAL_RESET_POWER_ON = 0,        /* or a start nothing can tell apart: not a fault */
    HAL_RESET_PLANNED = 1,         /* the firmware's own restart (an update): not a fault */
    HAL_RESET_FIRMWARE_FAULT = 10, /* a core fault, an unused interrupt, the stack guard */
    HAL_RESET_WATCHDOG = 11,       /* the independent watchdog: the main loop hung */
    HAL_RESET_SOFTWARE = 12,       /* a software reset the firmware did not plan */
    HAL_RESET_BROWN_OUT = 13,      /* the supply fell below the reset level; RAM held */
    HAL_RESET_PIN = 14,            /* the NRST pin, pulled from outside */
    HAL_RESET_LOW_POWER = 15,      /* the low-power reset (the firmware never asks for one) */
};

/* Resets since power-on, by kind (item 73's bytes, lowest first). */
enum hal_reset_count {
    HAL_COUNT_FIRMWARE_FAULT = 0,
    HAL_COUNT_WATCHDOG = 1,
    HAL_COUNT_OTHER = 2, /* software, pin, low-power */
    HAL_COUNT_BROWN_OUT = 3,
    HAL_RESET_COUNTS = 4,
};

/* Fault resets in a row that put the servo in safe mode (app/servo_safety.h):
 * a healthy run does not clear them once there, only a power-on or a planned
 * restart does. */
#define HAL_SAFE_MODE_RESETS 3u

/* The exception number a main loop's stack check reports (no exception). */
#define HAL_FAULT_STACK_GUARD 0u

/* From pc on laid out as the fault history's record of a firmware fault
 * (storage/fault_record.h, struct fault_code), which copies it whole. */
struct hal_reset {
    uint8_t kind;       /* enum hal_reset_kind */
    uint8_t in_row;     /* fault resets with no healthy run between, this one's included */
    uint8_t spare[2];
    uint8_t counts[HAL_RESET_COUNTS]; /* word-aligned: item 73's bytes in one load */
    uint32_t pc;        /* the faulting instruction's address, from the exception's frame */
    uint32_t lr;        /* the link register then */
    uint16_t sp_offset; /* a firmware fault's stack pointer less the RAM's base */
    uint16_t mm_bus_status; /* ARMv7-M CFSR bits 0-15 (MemManage, BusFault); 0 on ARMv6-M */
    uint8_t exception;  /* the exception taken (3 HardFault, 4-6 MemManage, BusFault,
                         * UsageFault, 16 on an interrupt), or HAL_FAULT_STACK_GUARD */
    uint8_t usage_status; /* ARMv7-M CFSR bits 16-19 and 24-25 in bits 0-5, HFSR VECTTBL
                           * in bit 6, FORCED in bit 7; 0 on ARMv6-M */
};

#endif
