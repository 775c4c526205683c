#include "storage/save_policy.h"

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

uint32_t save_policy_op_seconds(const struct save_policy *p)
{
    return p->op_seconds_at_boot + p->uptime_s;
}

uint32_t save_policy_budget(const struct save_policy *p)
{
    return SAVE_ALLOWANCE + save_policy_op_seconds(p) / p->seconds_per_save;
}

void save_policy_count_time(struct save_policy *p, uint32_t now_us)
{
    while (now_us - p->second_mark_us >= 1000000u) {
        p->second_mark_us += 1000000u;
        p->uptime_s++;
    }
}

bool save_policy_allows(const struct save_policy *p, const struct config_store *store)
{
    return store->sequence < save_policy_budget(p);
}

bool save_policy_may_retry(const struct save_policy *p, const struct config_store *store,
                           uint32_t now_us)
{
    return !store->failed || now_us - p->failed_at_us >= SAVE_RETRY_US;
}

void save_policy_outcome(struct save_policy *p, bool ok, uint32_t now_us)
{
    if (!ok) {
        p->failed_at_us = now_us;
    }
}
