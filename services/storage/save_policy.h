/* Whether the servo may write one more config record: never faster than
 * the flash's rated endurance allows over a 10-year life of operation.
 *
 * Wear budget: records written (the store's sequence number) may not pass
 *   SAVE_ALLOWANCE + operating seconds / seconds_per_save
 * where seconds_per_save spends SAVE_BUDGET_PERCENT of the pages' rated
 * cycles (pages x cycles x records per page) in SAVE_LIFE_SECONDS. The
 * operating time is stored with every record, so the budget holds across
 * power cycles; it only under-counts (time since the last save is lost at
 * power-off). A change beyond the budget is refused, not kept in RAM. */
#ifndef STORAGE_SAVE_POLICY_H
#define STORAGE_SAVE_POLICY_H

#include <stdbool.h>
#include <stdint.h>

#include "storage/config_store.h"

/* STM32F103 datasheet (DS5319), "Flash memory endurance and data
 * retention": NEND 10 kcycles minimum over the temperature range. */
#define FLASH_RATED_CYCLES 10000u
#define SAVE_LIFE_SECONDS (10u * 31536000u)
#define SAVE_BUDGET_PERCENT 90u
/* Saves a new servo may make before its operating time counts. */
#define SAVE_ALLOWANCE 1000u
/* A failed erase is tried again after this. */
#define SAVE_RETRY_US 1000000u

struct save_policy {
    uint32_t seconds_per_save;
    uint32_t op_seconds_at_boot;
    uint32_t uptime_s;
    uint32_t second_mark_us;
    uint32_t failed_at_us;    /* the last failed flash step */
    uint8_t over_budget;      /* the last change was refused: wear budget */
    uint8_t awaits_erase;     /* the last change was refused: no erased slot */
};

/* After config_store_load. Divides (once). */
void save_policy_init(struct save_policy *p, const struct config_store *store, uint32_t now_us);
/* Counts operating time; called at least once a second. */
void save_policy_count_time(struct save_policy *p, uint32_t now_us);
/* One more record is within the wear budget. */
bool save_policy_allows(const struct save_policy *p, const struct config_store *store);
/* The outcome of a save or an erase: a failure is not retried (an erase)
 * within SAVE_RETRY_US. */
void save_policy_outcome(struct save_policy *p, bool ok, uint32_t now_us);
/* Not within SAVE_RETRY_US of a failed flash step. */
bool save_policy_may_retry(const struct save_policy *p, const struct config_store *store,
                           uint32_t now_us);
/* Another record (the fault history's) counts more operating time than
 * the store's last: the time goes on from there. */
static inline void save_policy_carry_op_seconds(struct save_policy *p, uint32_t seen)
{
    if (seen > p->op_seconds_at_boot) {
        p->op_seconds_at_boot = seen;
    }
}
/* Operating seconds so far, across power cycles (as recorded). */
uint32_t save_policy_op_seconds(const struct save_policy *p);
/* Records the budget allows by now. */
uint32_t save_policy_budget(const struct save_policy *p);

#endif
