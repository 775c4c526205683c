/* The fault history in two flash pages of its own, apart from the config
 * store's, so that nothing it does can cost the config store a record.
 *
 * Each page is a log of 32-byte records (a fault, or a ClearFaults marker),
 * each with its number (one more than the newest before it) and a CRC-32
 * programmed last: a record cut by a power loss is never read. A record
 * goes in the first erased slot after the newest; when that page is full,
 * the other page is erased (it holds only older records: the full page
 * has more than FAULT_HISTORY newer ones) and the log goes on there. The
 * erase waits for a moment when its CPU stall costs nothing, as the config
 * store's does (app/servo.h); records wait in RAM meanwhile.
 *
 * Writes: a write block a step, from the main loop (fault_log_step), so no
 * step stalls the CPU for longer than one program (70 us on the F1).
 * Wear: a kind of fault that trips again within FAULT_REPEAT_S of its last
 * record, and faults beyond a wear budget like the config store's
 * (FAULT_ALLOWANCE + operating seconds / FAULT_SECONDS_PER_RECORD, which
 * spends 90 % of the two pages' 10 000 cycles in 10 years), are counted,
 * not written. */
#ifndef STORAGE_FAULT_LOG_H
#define STORAGE_FAULT_LOG_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal_flash.h"
#include "hal/must_check.h"
#include "storage/fault_record.h"

#define FAULT_RECORD_SIZE 32u
#define FAULT_PENDING_MAX 4u
#define FAULT_REPEAT_S 10u
#define FAULT_ALLOWANCE 1000u
/* 10 years / (2 pages x 10 000 cycles x 32 records x 90 %) */
#define FAULT_SECONDS_PER_RECORD 547u
/* Slots a log can hold (two pages of up to 2 KB each). */
#define FAULT_SLOTS_MAX 128u

struct fault_log {
    const struct hal_flash *flash; /* NULL: a port without one (nothing kept) */
    uint32_t newest;        /* number of the newest record; 0 none */
    uint8_t page;           /* where it is */
    uint8_t slot;
    uint8_t spare_erased;   /* the other page is all 0xFF */
    uint8_t blank_page1_erased; /* a blank log's page 1, looked at on load */
    uint8_t next_page;      /* where the next record goes */
    uint8_t next_slot;
    uint8_t shown_count;    /* faults after the newest clear, up to FAULT_HISTORY */
    uint8_t shown[FAULT_HISTORY]; /* their slots (page x slots + slot), newest first */
    struct fault_entry pending[FAULT_PENDING_MAX];
    uint8_t pending_count;
    uint8_t job_active;     /* pending[0] is being programmed */
    uint8_t job_page;
    uint8_t job_slot;
    uint16_t job_next;
    uint8_t job[FAULT_RECORD_SIZE];
    uint32_t last_seen[FAULT_OSCILLATION + 1]; /* each kind's last record's second + 1; 0 none */
    uint16_t not_logged;    /* repeats, over the budget, or no room: since power-up */
    uint32_t failures;      /* program or erase steps the flash refused */
};

/* Finds the newest records; flash NULL keeps nothing. Returns the
 * operating second after the latest of them (0 none): the operating time
 * goes on from there at power-up. */
uint32_t fault_log_load(struct fault_log *l, const struct hal_flash *flash);
/* Queues a fault (or a FAULT_CLEARED marker) to be written; the entry's
 * number is the log's to give. False when it is not logged (a fault is
 * counted), and for a clear that would have to wait for an erase. */
bool fault_log_add(struct fault_log *l, const struct fault_entry *e);
/* Programs the next write block of a queued record, if any may go now:
 * true when flash work was done. */
bool fault_log_step(struct fault_log *l);
/* The page without the newest record wants its erase: the page in use is
 * full, or the spare holds no fault shown any more. */
bool fault_log_spare_dirty(const struct fault_log *l);
MUST_CHECK bool fault_log_erase_spare(struct fault_log *l);
/* The index-th newest fault shown (0 the newest), as its bytes (struct
 * fault_entry's image, FAULT_ENTRY_BYTES): false beyond. log is a struct
 * fault_log: the form ReadFaults calls back (dispatcher.h), with no call
 * between, which took the M0's answer past its 30 us. */
bool fault_log_read(void *log, uint8_t index, uint8_t *out);

#endif
