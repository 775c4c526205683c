/* When the servo writes its user area to flash: soon after a change, a
 * burst of changes as one save, and never faster than the flash's rated
 * endurance allows over a 10-year life of operation.
 *
 * Wear budget: records written (the store's sequence number) may not pass
 *   SAVE_ALLOWANCE + operating seconds / seconds_per_save
 * where seconds_per_save spends SAVE_BUDGET_PERCENT of the pages' rated
 * cycles (pages x cycles x records per page) in SAVE_LIFE_SECONDS. The
 * operating time is stored with every record, so the budget holds across
 * power cycles; it only under-counts (time since the last save is lost at
 * power-off). A change beyond the budget waits, coalesced with later ones,
 * until the operating time allows it. */
#ifndef STORAGE_SAVE_POLICY_H
#define STORAGE_SAVE_POLICY_H

#include <stdbool.h>
#include <stdint.h>

#include "config_store.h"

/* STM32F103 datasheet (DS5319), "Flash memory endurance and data
 * retention": NEND 10 kcycles minimum over the temperature range. */
#define FLASH_RATED_CYCLES 10000u
#define SAVE_LIFE_SECONDS (10u * 31536000u)
#define SAVE_BUDGET_PERCENT 90u
/* Saves a new servo may make before its operating time counts. */
#define SAVE_ALLOWANCE 1000u
/* A change is saved once nothing has changed for SAVE_SETTLE_US, or
 * SAVE_LATEST_US after the first unsaved change while changes go on. */
#define SAVE_SETTLE_US 50000u
#define SAVE_LATEST_US 1000000u
/* A failed save is tried again after this. */
#define SAVE_RETRY_US 1000000u

struct save_policy {
    uint32_t seconds_per_save;
    uint32_t op_seconds_at_boot;
    uint32_t uptime_s;
    uint32_t second_mark_us;
    uint32_t first_change_us;
    uint32_t last_change_us;
    uint32_t failed_at_us;
    uint8_t pending;   /* a change not yet saved */
    uint8_t deferred;  /* the wear budget holds the pending change back */
    uint8_t awaits_erase; /* the pending change needs the other page erased */
    uint32_t awaits_erase_since_us;
};

/* After config_store_load. Divides (once). */
void save_policy_init(struct save_policy *p, const struct config_store *store, uint32_t now_us);
/* The user area changed now. */
void save_policy_changed(struct save_policy *p, uint32_t now_us);
/* Counts operating time; true when the pending change should be saved now. */
bool save_policy_due(struct save_policy *p, const struct config_store *store, uint32_t now_us);
/* The save save_policy_due asked for needs the other page erased first. */
void save_policy_awaits_erase(struct save_policy *p, uint32_t now_us);
/* Not within SAVE_RETRY_US of a failed flash step (a save or an erase). */
bool save_policy_may_retry(const struct save_policy *p, const struct config_store *store,
                           uint32_t now_us);
/* The save save_policy_due asked for has taken the user area as it is now:
 * a change from here on is pending again. */
void save_policy_started(struct save_policy *p);
/* The outcome of that save. A failed one is pending again, retried after
 * SAVE_RETRY_US. */
void save_policy_saved(struct save_policy *p, enum config_save_result result, uint32_t now_us);
/* Operating seconds so far, across power cycles (as recorded). */
uint32_t save_policy_op_seconds(const struct save_policy *p);
/* Records the budget allows by now. */
uint32_t save_policy_budget(const struct save_policy *p);

#endif
