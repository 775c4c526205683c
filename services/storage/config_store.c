#include "storage/config_store.h"

#include <string.h>

#include "storage/config_record.h"
#include "runtime/crc32.h"
#include "storage/flash_erased.h"
#include "registers/byte_order.h"
#include "registers/data_table.h"
#include "hal/size_first.h"

uint16_t config_store_slots_per_page(const struct config_store *s)
{
    return (uint16_t)(s->flash->page_size / CONFIG_RECORD_SIZE);
}

SIZE_FIRST_CALLED static uint32_t slot_addr(const struct config_store *s, uint8_t page,
                                            uint16_t slot, uint32_t size)
{
    return s->flash->page_addr[page] + (uint32_t)slot * size;
}

/* Where the fields of each record format are, newest format first. */
struct record_layout {
    uint8_t format;
    uint8_t size;
    uint8_t payload;
    uint8_t crc;
    uint8_t length; /* payload bytes: the user area, and the drive area from format 3 */
};
static const struct record_layout FORMATS[] = {
    {RECORD_FORMAT, CONFIG_RECORD_SIZE, REC_PAYLOAD, REC_CRC, STORED_SIZE},
    {V2_FORMAT, V2_RECORD_SIZE, REC_PAYLOAD, V2_CRC, USER_AREA_SIZE},
#ifndef SERVO_SIZE_FIRST /* the Cortex-M0 board came after format 2: none of its stores is older */
    {V1_FORMAT, V1_RECORD_SIZE, V1_PAYLOAD, V1_CRC, USER_AREA_SIZE},
#endif
};

/* A record whose every field checks out, including the item ranges: a
 * record from a firmware with other ranges is not loaded half-valid. A
 * format without the drive area leaves out's as it was. */
static bool record_valid(const uint8_t *rec, const struct record_layout *l, struct user_config *out)
{
    if (le_get_u16(&rec[REC_MAGIC]) != RECORD_MAGIC || rec[REC_FORMAT] != l->format ||
        rec[REC_LENGTH] != l->length || le_get_u32(&rec[REC_SEQUENCE]) == 0u ||
        le_get_u32(&rec[l->crc]) != crc32(rec, l->crc)) {
        return false;
    }
    return user_config_decode(out, &rec[l->payload], l->length);
}

static bool slot_erased(const struct config_store *s, uint8_t page, uint16_t slot)
{
    return flash_erased(s->flash, slot_addr(s, page, slot, CONFIG_RECORD_SIZE), CONFIG_RECORD_SIZE);
}

/* The newest valid record of one format in both pages, if newer than what
 * the store holds: it becomes the store's newest. */
static bool scan(struct config_store *s, const struct record_layout *l, struct user_config *newest)
{
    bool found = false;
    const uint16_t slots = (uint16_t)(s->flash->page_size / l->size);
    for (uint8_t page = 0; page < 2u; page++) {
        for (uint16_t slot = 0; slot < slots; slot++) {
            uint8_t rec[CONFIG_RECORD_SIZE];
            s->flash->read(s->flash->ctx, slot_addr(s, page, slot, l->size), rec, l->size);
            uint32_t seq = le_get_u32(&rec[REC_SEQUENCE]);
            /* Decoded over newest (the factory drive area, before format 3),
             * which it changes only when the record is valid. */
            if (seq > s->sequence && record_valid(rec, l, newest)) {
                s->sequence = seq;
                s->page = page;
                s->slot = slot;
                s->op_seconds = l->payload == REC_PAYLOAD ? le_get_u32(&rec[REC_OP_SECONDS]) : 0u;
                found = true;
            }
        }
    }
    return found;
}

/* The page without the newest record; for a blank store page 0, where the
 * first record goes. */
SIZE_FIRST_CALLED static uint8_t spare_page(const struct config_store *s)
{
    return (uint8_t)(s->sequence != 0u ? s->page ^ 1u : 0u);
}

static bool page_erased(const struct config_store *s, uint8_t page)
{
    return flash_erased(s->flash, s->flash->page_addr[page], s->flash->page_size);
}

bool config_store_load(struct config_store *s, const struct hal_flash *flash,
                       struct user_config *cfg)
{
    *s = (struct config_store){.flash = flash};
    struct user_config newest;
    user_config_factory(&newest);
    /* A store written by older firmware holds an older format only; the
     * next save starts a page in format 3. */
    for (uint8_t f = 0; f < sizeof FORMATS / sizeof FORMATS[0]; f++) {
        if (scan(s, &FORMATS[f], &newest)) {
            s->legacy = f != 0u;
            break;
        }
    }
    *cfg = newest;
    memcpy(s->saved, &newest, STORED_SIZE); /* its wire image (data_table.c) */
    s->spare_erased = page_erased(s, spare_page(s));
    /* A blank store's first record goes to page 0 and makes page 1 the
     * spare: look at it now, not while a write waits for its answer. */
    s->blank_page1_erased = s->sequence == 0u && page_erased(s, 1);
    return s->sequence != 0u;
}

uint32_t config_store_page_erases(const struct config_store *s)
{
    /* A page is erased each time records start on it: every slots-per-page
     * records, the two pages in turn. */
    uint32_t pages_started = (s->sequence + config_store_slots_per_page(s) - 1u) /
                             config_store_slots_per_page(s);
    return (pages_started + 1u) / 2u;
}

/* Where the next record goes: the first erased slot after the newest in its
 * page, else slot 0 of the other page (which must be erased first). */
static bool next_slot(const struct config_store *s, uint8_t *page, uint16_t *slot)
{
    const uint16_t slots = config_store_slots_per_page(s);
    if (s->legacy) {
        *page = (uint8_t)(s->page ^ 1u); /* an older format's page takes no format-3 slots */
    } else if (s->sequence != 0u) {
        for (uint16_t i = (uint16_t)(s->slot + 1u); i < slots; i++) {
            if (slot_erased(s, s->page, i)) {
                *page = s->page;
                *slot = i;
                return true;
            }
        }
        *page = (uint8_t)(s->page ^ 1u);
    } else {
        *page = 0;
    }
    *slot = 0;
    return false;
}

enum config_save_result config_store_begin(struct config_store *s, const struct user_config *cfg,
                                           uint32_t op_seconds)
{
    uint8_t *rec = s->job;
    memcpy(&rec[REC_PAYLOAD], cfg, STORED_SIZE); /* its wire image (data_table.c) */
    /* An older format is written again in format 3 even unchanged: the
     * bootloader reads format 3 only (config_peek.c). */
    if (!s->legacy && memcmp(&rec[REC_PAYLOAD], s->saved, STORED_SIZE) == 0) {
        return CONFIG_UNCHANGED;
    }
    uint8_t page;
    uint16_t slot;
    if (!next_slot(s, &page, &slot) && page == spare_page(s) && !s->spare_erased) {
        return CONFIG_NEEDS_ERASE;
    }
    le_put_u16(&rec[REC_MAGIC], RECORD_MAGIC);
    rec[REC_FORMAT] = RECORD_FORMAT;
    rec[REC_LENGTH] = STORED_SIZE;
    le_put_u32(&rec[REC_SEQUENCE], s->sequence + 1u);
    le_put_u32(&rec[REC_OP_SECONDS], op_seconds);
    memset(&rec[REC_PADDING], 0xFF, REC_CRC - REC_PADDING); /* erased, as flash is */
    le_put_u32(&rec[REC_CRC], crc32(rec, REC_CRC));
    s->job_active = 1;
    s->job_page = page;
    s->job_slot = slot;
    s->job_next = 0;
    s->job_op_seconds = op_seconds;
    return CONFIG_STARTED;
}

static enum config_save_result save_failed(struct config_store *s)
{
    s->write_failures++;
    s->failed = 1;
    return CONFIG_WRITE_FAILED;
}

enum config_save_result config_store_step(struct config_store *s)
{
    /* Block by block in order: the CRC, in the last block, lands last. */
    uint32_t block = s->flash->write_block;
    uint32_t addr = slot_addr(s, s->job_page, s->job_slot, CONFIG_RECORD_SIZE) + s->job_next;
    /* A block of 2, 4 or 8 (hal_flash.h) divides the record: a mask, where
     * a division is a loop on the Cortex-M0 (and this runs per block). */
    if (block == 0u || (block & (block - 1u)) != 0u || (CONFIG_RECORD_SIZE & (block - 1u)) != 0u ||
        !s->flash->program(s->flash->ctx, addr, &s->job[s->job_next])) {
        /* The sequence number is spent: should the record have landed after
         * all, no later record may share its number. */
        s->job_active = 0;
        if (s->job_page == spare_page(s)) {
            s->spare_erased = 0;
        }
        s->sequence++;
        return save_failed(s);
    }
    s->job_next = (uint16_t)(s->job_next + block);
    if (s->job_next < CONFIG_RECORD_SIZE) {
        return CONFIG_BUSY;
    }
    s->job_active = 0;
    bool was_blank = s->sequence == 0u;
    bool new_page = s->job_page == spare_page(s);
    s->sequence++;
    s->page = s->job_page;
    s->slot = s->job_slot;
    if (new_page) {
        /* The old page is the spare now: it holds records, unless this was
         * the first record of a blank store (page 1, looked at on load). */
        s->spare_erased = was_blank && s->blank_page1_erased;
    }
    s->legacy = 0;
    s->failed = 0;
    s->op_seconds = s->job_op_seconds;
    memcpy(s->saved, &s->job[REC_PAYLOAD], STORED_SIZE);
    return CONFIG_SAVED;
}

bool config_store_spare_dirty(const struct config_store *s)
{
    return !s->spare_erased && !s->job_active;
}

bool config_store_erase_spare(struct config_store *s)
{
    uint8_t page = spare_page(s);
    if (!s->flash->erase_page(s->flash->ctx, s->flash->page_addr[page])) {
        save_failed(s);
        return false;
    }
    s->spare_erased = 1;
    return true;
}
