/* The register file: one struct per area of the data table
 * (docs/protocol.md), in protocol units. */
#ifndef REGISTERS_REGISTERS_H
#define REGISTERS_REGISTERS_H

#include <stdint.h>

/* struct status_area, enum status_bit, struct user_config, USER_AREA_SIZE,
 * struct firmware_area and each writable item's range: made from
 * protocol/servo_schema. */
#include "registers/schema_items.h"

/* How the config store is doing (ReadStore, 0x41, docs/packets.md): kept
 * up to date by the application, read by the dispatcher. */
enum store_flag {
    STORE_FAILED = 1u << 0,      /* the flash refused the last save or erase */
    STORE_OVER_BUDGET = 1u << 1, /* the last change was refused: wear budget */
    STORE_UNSTABLE = 1u << 2,    /* the last change was refused: the drive items
                                  * would make the loop unstable (drive_items_stable) */
    STORE_AWAITS_ERASE = 1u << 3, /* the last change was refused: no erased slot */
};

struct store_health {
    uint8_t flags;          /* enum store_flag */
    uint8_t write_refused;  /* the last WriteData's own refusal: STORE_UNSTABLE or 0 */
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
    /* The fault history (ReadFaults): faults shown, and faults not written
     * since power-up (storage/fault_log.h). */
    uint8_t fault_count;
    uint16_t faults_not_logged;
};

struct registers {
    struct status_area status;
    struct user_config user;
    struct firmware_area firmware;
    struct store_health store;
    /* What a protection or the watchdog holds the output back by (enum
     * limiter, motion/motion.h; 0 none): item 67 is this, else the motion's own limit. */
    uint8_t held_by;
};

/* The link settings' ranges and factory baud rate (items 34 and 36), which
 * the bootloader checks without the data table. */
#define SERVO_ID_MAX ITEM_SERVO_ID_MAX
#define BAUD_INDEX_MIN ITEM_BAUD_INDEX_MIN
#define BAUD_INDEX_MAX ITEM_BAUD_INDEX_MAX
#define BAUD_INDEX_FACTORY ITEM_BAUD_INDEX_FACTORY

#endif
