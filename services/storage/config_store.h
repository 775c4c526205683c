/* Power-safe store of the user and drive areas in two flash pages.
 *
 * Each page is a log of fixed-size records: magic, format, length, sequence
 * number, the operating time so far, the 32-byte user area, the drive area
 * and a CRC-32 over all of it. A save appends a record with the next sequence number to
 * the first erased slot after the newest record; when that page is full it
 * starts on the other page. The page holding the newest record is never
 * erased, and a record is only valid once its CRC (programmed last)
 * matches, so a power cut at any instant leaves the old or the new record
 * as the newest valid one.
 *
 * The CPU stalls while the flash works (it fetches from it), so the
 * application saves in steps: config_store_begin() takes the record,
 * config_store_step() programs one write block a call (52.5 us on the
 * STM32F1), and the other page is erased ahead of time, when a stall of
 * 20-40 ms costs nothing (config_store_erase_spare()). config_store_save()
 * does it all at once, for tools and tests. */
#ifndef STORAGE_CONFIG_STORE_H
#define STORAGE_CONFIG_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "storage/config_record.h"
#include "hal/hal_flash.h"
#include "hal/must_check.h"
#include "registers/registers.h"

enum config_save_result {
    CONFIG_UNCHANGED,    /* identical to the stored record: nothing written */
    CONFIG_SAVED,
    CONFIG_WRITE_FAILED, /* flash refused an erase or program step */
    CONFIG_STARTED,      /* config_store_begin: call config_store_step */
    CONFIG_BUSY,         /* config_store_step: more blocks to go */
    CONFIG_NEEDS_ERASE,  /* config_store_begin: the other page is not erased yet */
};

struct config_store {
    const struct hal_flash *flash;
    uint32_t sequence;   /* of the newest valid record; 0 when none */
    uint8_t page;        /* where the newest record is */
    uint16_t slot;
    uint8_t saved[STORED_SIZE]; /* what a boot would load now */
    uint32_t op_seconds; /* operating time recorded with the newest record */
    uint32_t write_failures;
    uint8_t failed;      /* the last save failed (and nothing saved since) */
    uint8_t legacy;      /* the newest record is an older format: the next starts a page */
    uint8_t spare_erased; /* the page without the newest record is all 0xFF */
    uint8_t blank_page1_erased; /* a blank store's page 1 was all 0xFF on load */
    /* The save in progress: its record, where it goes, the next block. */
    uint8_t job[CONFIG_RECORD_SIZE];
    uint8_t job_active;
    uint8_t job_page;
    uint16_t job_slot;
    uint16_t job_next;
    uint32_t job_op_seconds;
};

/* Loads the newest valid record into cfg; factory values when the store is
 * blank or corrupt (and the drive area's when the record is older than
 * format 3). Returns true when a record was found. */
bool config_store_load(struct config_store *s, const struct hal_flash *flash,
                       struct user_config *cfg);

/* Starts appending cfg, with the operating time so far: CONFIG_STARTED,
 * CONFIG_UNCHANGED when cfg equals what is stored (and the store is in
 * format 3), CONFIG_NEEDS_ERASE when
 * the record must start the other page and that is not erased yet. */
MUST_CHECK enum config_save_result config_store_begin(struct config_store *s, const struct user_config *cfg,
                                           uint32_t op_seconds);
/* Programs the next write block of the save begun (only after
 * CONFIG_STARTED or CONFIG_BUSY): CONFIG_BUSY, then CONFIG_SAVED or
 * CONFIG_WRITE_FAILED. */
MUST_CHECK enum config_save_result config_store_step(struct config_store *s);
/* The page without the newest record holds something: erase it ahead. */
bool config_store_spare_dirty(const struct config_store *s);
/* Erases that page (a 20-40 ms stall on the STM32F1). False on failure. */
MUST_CHECK bool config_store_erase_spare(struct config_store *s);

/* All of a save at once: begin, erase if needed, every step
 * (config_store_save.c). */
MUST_CHECK enum config_save_result config_store_save(struct config_store *s, const struct user_config *cfg,
                                          uint32_t op_seconds);

/* Erases of the more worn page so far, from the records written (every
 * record counts, failed ones too: each spends a slot). */
uint32_t config_store_page_erases(const struct config_store *s);

/* Records that fit in one page. */
uint16_t config_store_slots_per_page(const struct config_store *s);

#endif
