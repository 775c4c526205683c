#include "storage/fault_log.h"

#include <stddef.h>
#include <string.h>

#include "registers/byte_order.h"
#include "runtime/crc32.h"
#include "storage/flash_erased.h"

/* The record: magic u16, format u8, 0xFF, the entry's bytes
 * (FAULT_ENTRY_BYTES, struct fault_entry's image), 0xFF, CRC-32 over bytes
 * 0-27. */
enum {
    FR_MAGIC = 0,
    FR_FORMAT = 2,
    FR_ENTRY = 4,
    FR_NUMBER = FR_ENTRY + offsetof(struct fault_entry, number),
    FR_WHAT = FR_ENTRY + offsetof(struct fault_entry, what),
    FR_OP_SECONDS = FR_ENTRY + offsetof(struct fault_entry, op_seconds),
    FR_CRC = 28,
    FAULT_MAGIC = 0xFA17,
    FAULT_FORMAT = 1,
};
_Static_assert(FR_ENTRY + FAULT_ENTRY_BYTES < FR_CRC && FR_CRC + 4 == FAULT_RECORD_SIZE,
               "record layout");
_Static_assert(offsetof(struct fault_entry, what) + 1u == FAULT_ENTRY_BYTES &&
                   __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
               "an entry is its record's bytes");

static uint8_t slots_per_page(const struct fault_log *l)
{
    uint32_t n = l->flash->page_size / FAULT_RECORD_SIZE;
    return (uint8_t)(n > FAULT_SLOTS_MAX / 2u ? FAULT_SLOTS_MAX / 2u : n);
}

static uint32_t slot_addr(const struct fault_log *l, uint8_t page, uint8_t slot)
{
    return l->flash->page_addr[page] + (uint32_t)slot * FAULT_RECORD_SIZE;
}

static void read_record(const struct fault_log *l, uint8_t page, uint8_t slot,
                        uint8_t rec[FAULT_RECORD_SIZE])
{
    l->flash->read(l->flash->ctx, slot_addr(l, page, slot), rec, FAULT_RECORD_SIZE);
}

static bool record_valid(const uint8_t *rec)
{
    return le_get_u16(&rec[FR_MAGIC]) == FAULT_MAGIC && rec[FR_FORMAT] == FAULT_FORMAT &&
           le_get_u32(&rec[FR_NUMBER]) != 0u && le_get_u32(&rec[FR_CRC]) == crc32(rec, FR_CRC);
}


static void encode(const struct fault_entry *e, uint8_t *rec)
{
    memset(rec, 0xFF, FAULT_RECORD_SIZE);
    le_put_u16(&rec[FR_MAGIC], FAULT_MAGIC);
    rec[FR_FORMAT] = FAULT_FORMAT;
    memcpy(&rec[FR_ENTRY], e, FAULT_ENTRY_BYTES);
    le_put_u32(&rec[FR_CRC], crc32(rec, FR_CRC));
}

/* A shown fault's place: page << SHOWN_PAGE_SHIFT | slot (no division
 * when it is read). */
#define SHOWN_PAGE_SHIFT 6
_Static_assert(FAULT_SLOTS_MAX / 2u <= 1u << SHOWN_PAGE_SHIFT, "a slot fits below the page bit");

/* A record now the newest: shown in front, or a clear that hides the rest. */
static void show(struct fault_log *l, uint8_t what, uint8_t page, uint8_t slot)
{
    if (what == FAULT_CLEARED) {
        l->shown_count = 0;
        return;
    }
    for (unsigned i = FAULT_HISTORY - 1u; i > 0u; i--) {
        l->shown[i] = l->shown[i - 1u];
    }
    l->shown[0] = (uint8_t)(page << SHOWN_PAGE_SHIFT | slot);
    if (l->shown_count < FAULT_HISTORY) {
        l->shown_count++;
    }
}

static bool page_erased(const struct fault_log *l, uint8_t page)
{
    return flash_erased(l->flash, l->flash->page_addr[page], l->flash->page_size);
}

/* Where the next record goes: the first erased slot after the newest in
 * its page, else slot 0 of the other page (erased first). Worked out when
 * the newest or the spare changes, not at each step: it reads the page. */
static void plan_next(struct fault_log *l)
{
    const uint8_t slots = slots_per_page(l);
    for (uint8_t i = (uint8_t)(l->slot + 1u); i < slots; i++) {
        if (flash_erased(l->flash, slot_addr(l, l->page, i), FAULT_RECORD_SIZE)) {
            l->next_page = l->page;
            l->next_slot = i;
            return;
        }
    }
    l->next_page = (uint8_t)(l->page ^ 1u);
    l->next_slot = 0;
}

/* A record find_below found: its place (as shown: page <<
 * SHOWN_PAGE_SHIFT | slot), kind, number and operating second. */
struct found {
    uint32_t number;
    uint32_t op_seconds;
    uint8_t at;
    uint8_t what;
};

/* The valid record with the largest number below `below` (f->number 0:
 * none). */
static bool find_below(const struct fault_log *l, uint32_t below, struct found *f)
{
    const uint8_t slots = slots_per_page(l);
    uint8_t rec[FAULT_RECORD_SIZE];
    f->number = 0;
    for (uint8_t page = 0; page < 2u; page++) {
        for (uint8_t slot = 0; slot < slots; slot++) {
            read_record(l, page, slot, rec);
            uint32_t n = le_get_u32(&rec[FR_NUMBER]);
            if (n < below && n > f->number && record_valid(rec)) {
                f->number = n;
                f->at = (uint8_t)(page << SHOWN_PAGE_SHIFT | slot);
                f->what = rec[FR_WHAT];
                f->op_seconds = le_get_u32(&rec[FR_OP_SECONDS]);
            }
        }
    }
    return f->number != 0u;
}

/* A kind's slot in last_seen, for the repeat rule. The firmware's own
 * resets (10-12, 15) have none (FAULT_CLEARED's slot, which clears do not
 * use): the application logs at most three in a row. The supply's and the
 * pin's (13, 14), which a weak supply could repeat at every start, share
 * slot 1 (no kind of its own) and keep the rule. */
static uint8_t repeat_slot(uint8_t what)
{
    return what <= FAULT_OSCILLATION                          ? what
           : what == FAULT_BROWN_OUT || what == FAULT_RESET_PIN ? 1u
                                                                : FAULT_CLEARED;
}

uint32_t fault_log_load(struct fault_log *l, const struct hal_flash *flash)
{
    *l = (struct fault_log){.flash = flash};
    uint32_t latest = 0;
    if (flash == NULL) {
        return latest;
    }
    /* The newest record, then each next older one (a failed record's
     * number is spent, so numbers may skip), up to a clear or the history's
     * length: at power-up, while nobody waits. Each kind's newest of them
     * sets its last_seen, so that the repeat rule goes on across power
     * cycles, and so does the operating time (from the newest's). */
    struct found f;
    if (find_below(l, UINT32_MAX, &f)) {
        l->newest = f.number;
        l->page = (uint8_t)(f.at >> SHOWN_PAGE_SHIFT);
        l->slot = (uint8_t)(f.at & ((1u << SHOWN_PAGE_SHIFT) - 1u));
        latest = f.op_seconds + 1u;
        for (;;) {
            uint8_t kind = repeat_slot(f.what);
            if (l->last_seen[kind] == 0u) {
                l->last_seen[kind] = f.op_seconds + 1u;
            }
            if (f.what == FAULT_CLEARED) {
                break;
            }
            l->shown[l->shown_count++] = f.at;
            if (l->shown_count == FAULT_HISTORY || !find_below(l, f.number, &f)) {
                break;
            }
        }
    }
    if (l->newest == 0u) {
        /* A blank log starts on page 0 as if page 1 were full: page 0 is
         * the spare, and page 1 becomes it once the first record is in. */
        l->page = 1;
        l->slot = (uint8_t)(slots_per_page(l) - 1u);
        l->blank_page1_erased = page_erased(l, 1);
    }
    l->spare_erased = page_erased(l, (uint8_t)(l->page ^ 1u));
    plan_next(l);
    return latest;
}

bool fault_log_add(struct fault_log *l, const struct fault_entry *e)
{
    uint8_t what = repeat_slot(e->what);
    /* last_seen: each kind's last record's operating second + 1; 0 none.
     * A fault is held back as a repeat; a clear, promised within
     * milliseconds, where its record could wait for an erase (no erased
     * spare, and the page in use full or records queued before it: it is
     * refused, and taken once they are written). */
    uint32_t since = e->op_seconds + 1u - l->last_seen[what];
    bool held_back = e->what == FAULT_CLEARED
                         ? !l->spare_erased && (l->next_page != l->page || l->pending_count != 0u)
                         : what != FAULT_CLEARED && l->last_seen[what] != 0u && since < FAULT_REPEAT_S;
    uint32_t records = l->newest + l->pending_count;
    if (l->flash == NULL || held_back || l->pending_count == FAULT_PENDING_MAX ||
        (records >= FAULT_ALLOWANCE &&
         records >= FAULT_ALLOWANCE + e->op_seconds / FAULT_SECONDS_PER_RECORD)) {
        l->not_logged = (uint16_t)(l->not_logged + (l->not_logged != UINT16_MAX));
        return false;
    }
    l->last_seen[what] = e->op_seconds + 1u;
    l->pending[l->pending_count++] = *e;
    return true;
}

static void job_done(struct fault_log *l, bool ok)
{
    l->job_active = 0;
    l->pending_count--;
    for (unsigned i = 0; i < l->pending_count; i++) {
        l->pending[i] = l->pending[i + 1u];
    }
    bool first = l->newest == 0u;
    bool new_page = l->job_page != l->page;
    l->newest++; /* a failed record spends its number too */
    if (new_page) {
        /* Failed, the record's page holds a part of it; done, the old page
         * is the spare, with records (unless this is a blank log's first). */
        l->spare_erased = ok && first && l->blank_page1_erased;
    }
    if (ok) {
        l->page = l->job_page;
        l->slot = l->job_slot;
        show(l, l->job[FR_WHAT], l->page, l->slot);
    } else {
        l->failures++;
    }
    plan_next(l);
}

bool fault_log_step(struct fault_log *l)
{
    if (l->pending_count == 0u) {
        return false;
    }
    if (!l->job_active) {
        if (l->next_page != l->page && !l->spare_erased) {
            return false; /* waits for the erase */
        }
        struct fault_entry e = l->pending[0];
        e.number = l->newest + 1u;
        encode(&e, l->job);
        l->job_active = 1;
        l->job_page = l->next_page;
        l->job_slot = l->next_slot;
        l->job_next = 0;
    }
    uint32_t block = l->flash->write_block;
    uint32_t addr = slot_addr(l, l->job_page, l->job_slot) + l->job_next;
    bool ok = block != 0u && FAULT_RECORD_SIZE % block == 0u &&
              l->flash->program(l->flash->ctx, addr, &l->job[l->job_next]);
    if (ok) {
        l->job_next = (uint16_t)(l->job_next + block);
        if (l->job_next != FAULT_RECORD_SIZE) {
            return true;
        }
    }
    job_done(l, ok); /* one call: the M0 keeps one copy of it */
    return true;
}

/* The spare may be erased as soon as it holds no fault shown (the oldest
 * shown is in the page in use): ahead of need, as the config store's is,
 * so that a page that fills while the output is driven (no erase then)
 * finds the next one ready. Still one erase a page's turn: no more wear. */
bool fault_log_spare_dirty(const struct fault_log *l)
{
    uint8_t shown = l->shown_count;
    bool spare_shown = shown != 0u && (l->shown[shown - 1u] >> SHOWN_PAGE_SHIFT) != l->page;
    return l->flash != NULL && !l->spare_erased && !l->job_active &&
           (l->next_page != l->page || !spare_shown);
}

bool fault_log_erase_spare(struct fault_log *l)
{
    uint8_t spare = (uint8_t)(l->page ^ 1u);
    if (!l->flash->erase_page(l->flash->ctx, l->flash->page_addr[spare])) {
        l->failures++;
        return false;
    }
    l->spare_erased = 1;
    return true;
}

bool fault_log_read(void *log, uint8_t index, uint8_t *out)
{
    const struct fault_log *l = log;
    if (index >= l->shown_count) {
        return false;
    }
    uint8_t at = l->shown[index];
    uint32_t addr = slot_addr(l, (uint8_t)(at >> SHOWN_PAGE_SHIFT),
                              (uint8_t)(at & ((1u << SHOWN_PAGE_SHIFT) - 1u)));
    l->flash->read(l->flash->ctx, addr + FR_ENTRY, out, FAULT_ENTRY_BYTES);
    return true;
}
