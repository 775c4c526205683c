#include "save_policy.h"

void save_policy_init(struct save_policy *p, const struct config_store *store, uint32_t now_us)
{
    /* 32 bits do: 2 pages x 10 000 cycles x at most 65 535 slots is below
     * 2^31, and a multiple of 100, so taking the percentage after the
     * division is exact. */
    uint32_t lifetime = 2u * FLASH_RATED_CYCLES * config_store_slots_per_page(store);
    uint32_t budget = lifetime / 100u * SAVE_BUDGET_PERCENT - SAVE_ALLOWANCE;
    uint32_t per_save = (SAVE_LIFE_SECONDS + budget - 1u) / budget;
    *p = (struct save_policy){
        .seconds_per_save = (uint32_t)per_save,
        .op_seconds_at_boot = store->op_seconds,
        .second_mark_us = now_us,
    };
}

void save_policy_changed(struct save_policy *p, uint32_t now_us)
{
    if (!p->pending) {
        p->pending = 1;
        p->first_change_us = now_us;
    }
    p->last_change_us = now_us;
}

uint32_t save_policy_op_seconds(const struct save_policy *p)
{
    return p->op_seconds_at_boot + p->uptime_s;
}

uint32_t save_policy_budget(const struct save_policy *p)
{
    return SAVE_ALLOWANCE + save_policy_op_seconds(p) / p->seconds_per_save;
}

bool save_policy_due(struct save_policy *p, const struct config_store *store, uint32_t now_us)
{
    while (now_us - p->second_mark_us >= 1000000u) {
        p->second_mark_us += 1000000u;
        p->uptime_s++;
    }
    if (!p->pending) {
        return false;
    }
    if (!save_policy_may_retry(p, store, now_us)) {
        return false;
    }
    bool settled = now_us - p->last_change_us >= SAVE_SETTLE_US ||
                   now_us - p->first_change_us >= SAVE_LATEST_US;
    if (!settled) {
        return false;
    }
    p->deferred = store->sequence >= save_policy_budget(p);
    return !p->deferred;
}

bool save_policy_may_retry(const struct save_policy *p, const struct config_store *store,
                           uint32_t now_us)
{
    return !store->failed || now_us - p->failed_at_us >= SAVE_RETRY_US;
}

void save_policy_awaits_erase(struct save_policy *p, uint32_t now_us)
{
    p->awaits_erase = 1;
    p->awaits_erase_since_us = now_us;
}

void save_policy_started(struct save_policy *p)
{
    p->pending = 0;
    p->awaits_erase = 0;
}

void save_policy_saved(struct save_policy *p, enum config_save_result result, uint32_t now_us)
{
    if (result == CONFIG_WRITE_FAILED) {
        p->failed_at_us = now_us; /* pending again: tried after SAVE_RETRY_US */
        if (!p->pending) {
            p->pending = 1;
            p->first_change_us = now_us;
            p->last_change_us = now_us;
        }
        return;
    }
    p->pending = 0;
}
