/* RAM a reset keeps and start-up does not clear: the last BOARD_RAM_KEPT
 * bytes, left out of both images' linker scripts (hal/ports/stm32_common/linker). Its
 * last word keeps the bootloader (boot_jump.h); at its start, this record
 * tells the next start-up what the firmware knew of the reset: a fault it
 * took (a fault handler wrote it), a restart it meant, and what came
 * before since power-on. A magic and a CRC-32 make RAM that a power-on left
 * random read as no record; one that held through a reset with the
 * power-on flag set (a dip below the reset level) tells a brown-out. */
#ifndef STM32_KEPT_RAM_H
#define STM32_KEPT_RAM_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_reset.h"

#define KEPT_MAGIC 0x4B455054u /* "KEPT" */

enum kept_note {
    KEPT_NONE = 0,
    KEPT_FAULT = 1,   /* a fault handler's record waits for the next start */
    KEPT_PLANNED = 2, /* the firmware restarts on purpose (an update) */
};

struct kept_ram {
    uint32_t magic;
    struct hal_reset reset; /* the last reset's, as the port gives it (hal_port.reset) */
    uint8_t note;           /* enum kept_note */
    uint8_t link_id;        /* KEPT_PLANNED: the ID and baud index the application */
    uint8_t link_baud;      /* answered at, where its bootloader answers (kept_link) */
    uint8_t spare;
    uint32_t crc;           /* CRC-32 of the bytes before it */
};

extern struct kept_ram _kept_ram; /* the linker's: the kept bytes' start */

void kept_seal(struct kept_ram *k);
/* What the reset was, from the reset flags as read (RCC_CSR) and the kept
 * record, into k->reset; the record is then the next run's (counts on,
 * note cleared). */
void reset_classify(uint32_t csr, struct kept_ram *k);
/* reset_classify of this start's flags, which are then cleared: the
 * reset, kept in place. */
const struct hal_reset *reset_cause_take(void);
/* Before a restart the firmware means (UpdateEnter's): the ID and baud
 * index it answers at, which its bootloader then answers at too. */
void kept_note_planned(uint8_t id, uint8_t baud_index);
/* The bootloader's start: true with the link kept_note_planned left, when
 * the record (its magic) says the application restarted on purpose: the
 * application clears the note as it starts (reset_classify). No CRC here:
 * the bootloader of the small part has no room for it, and a power-on's
 * random RAM holds the magic and the note one time in 2^40. */
bool kept_link(uint8_t *id, uint8_t *baud_index);
/* The servo ran long enough without a fault: the next fault reset is the
 * first in a row again (not in safe mode: HAL_SAFE_MODE_RESETS). */
void kept_healthy(void);

#endif
