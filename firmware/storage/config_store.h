/* Power-safe store of the user area in two flash pages.
 *
 * Each page is a log of fixed-size records: magic, format, length, sequence
 * number, the operating time so far, the 32-byte user area and a CRC-32
 * over all of it. A save appends
 * a record with the next sequence number to the first erased slot after the
 * newest record; when that page is full it erases the other page and starts
 * there. The page holding the newest record is never erased, and a record
 * is only valid once its CRC (programmed last) matches, so a power cut at
 * any instant leaves the old or the new record as the newest valid one. */
#ifndef STORAGE_CONFIG_STORE_H
#define STORAGE_CONFIG_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"
#include "registers/registers.h"

#define CONFIG_RECORD_SIZE 48u

enum config_save_result {
    CONFIG_UNCHANGED,    /* identical to the stored record: nothing written */
    CONFIG_SAVED,
    CONFIG_WRITE_FAILED, /* flash refused an erase or program step */
};

struct config_store {
    const struct hal_flash *flash;
    uint32_t sequence;   /* of the newest valid record; 0 when none */
    uint8_t page;        /* where the newest record is */
    uint16_t slot;
    uint8_t saved[USER_AREA_SIZE]; /* what a boot would load now */
    uint32_t op_seconds; /* operating time recorded with the newest record */
    uint32_t write_failures;
    uint8_t failed;      /* the last save failed (and nothing saved since) */
    uint8_t legacy;      /* the newest record is format 1: the next starts a page */
};

/* Loads the newest valid record into cfg; factory values when the store is
 * blank or corrupt. Returns true when a record was found. */
bool config_store_load(struct config_store *s, const struct hal_flash *flash,
                       struct user_config *cfg);

/* Appends cfg, with the operating time so far, unless cfg equals what is
 * stored. Call from the main loop. */
enum config_save_result config_store_save(struct config_store *s, const struct user_config *cfg,
                                          uint32_t op_seconds);

/* Erases of the more worn page so far, from the records written (every
 * record counts, failed ones too: each spends a slot). */
uint32_t config_store_page_erases(const struct config_store *s);

/* Records that fit in one page. */
uint16_t config_store_slots_per_page(const struct config_store *s);

#endif
