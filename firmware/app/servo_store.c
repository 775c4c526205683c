/* The store's upkeep (servo_jobs.h): saves for the dispatcher, the spare
 * page's erase when it costs nothing, operating time and ReadStore's
 * register group. */
#include <stdbool.h>

#include "app/servo_jobs.h"
#include "hal/size_first.h"

/* ReadStore's flags (enum store_flag). On the M0 called (a tick's report and a
 * save's), not inlined twice. */
SIZE_FIRST_CALLED static uint8_t store_flags(const struct servo *s)
{
    return (uint8_t)((s->store.failed ? STORE_FAILED : 0u) |
                     (s->saver.over_budget ? STORE_OVER_BUDGET : 0u) |
                     (s->saver.awaits_erase ? STORE_AWAITS_ERASE : 0u));
}

/* ReadStore's register group, on a change or a new second only: it
 * divides. */
static void report_store(struct servo *s)
{
    struct store_health *h = &s->regs.store;
    uint8_t flags = store_flags(s);
    uint32_t op_seconds = save_policy_op_seconds(&s->saver);
    h->answers_dropped = s->answers_dropped;
    h->bytes_lost = s->rx_lost;
    h->fault_count = s->faults.shown_count;
    h->faults_not_logged = s->faults.not_logged;
    if (flags == h->flags && op_seconds == h->op_seconds && h->rated_cycles != 0u &&
        s->store.sequence == h->records && s->store.write_failures == h->failures) {
        return;
    }
    h->flags = flags;
    h->records = s->store.sequence;
    h->page_erases = config_store_page_erases(&s->store);
    h->rated_cycles = FLASH_RATED_CYCLES;
    h->budget = save_policy_budget(&s->saver);
    h->op_seconds = op_seconds;
    h->failures = s->store.write_failures;
}

/* The dispatcher's persist hook: a changed user or drive area goes to flash
 * before the write is answered, all its write blocks at once (36
 * half-words, 1.4-2.5 ms on the STM32F1; the ticks catch up after, the DMA
 * ring holds what arrives). A change that cannot be made durable now is refused, and
 * ReadStore says why: past the wear budget, no erased slot until the
 * output is released, or the flash refused. */
static bool save_now(struct servo *s, const struct user_config *cfg)
{
    uint32_t now = s->hal->bus.now_us(s->hal->ctx);
    s->saver.over_budget = !save_policy_allows(&s->saver, &s->store);
    if (s->saver.over_budget) {
        return false;
    }
    enum config_save_result r =
        config_store_begin(&s->store, cfg, save_policy_op_seconds(&s->saver));
    if (r == CONFIG_NEEDS_ERASE) {
        s->saver.awaits_erase = 1;
        return false;
    }
    while (r == CONFIG_STARTED || r == CONFIG_BUSY) {
        r = config_store_step(&s->store);
    }
    bool ok = r != CONFIG_WRITE_FAILED;
    save_policy_outcome(&s->saver, ok, now);
    return ok;
}

SERVO_JOB bool servo_persist_config(void *ctx, const struct user_config *cfg)
{
    struct servo *s = ctx;
    bool ok = save_now(s, cfg);
    /* A ReadStore right after the answer says why; the rest of its group
     * follows at the next tick (report_store). */
    s->regs.store.flags = store_flags(s);
    return ok;
}

/* A page erase stalls the CPU for 20-40 ms: bytes wait in the DMA ring,
 * ticks do not run. Only while the output is released and the line is
 * quiet (servo.h, STORE_ERASE_*). */
static bool erase_may_stall(const struct servo *s, uint32_t now)
{
    const struct hal_rx_ring *ring = s->hal->rx;
    const uint32_t quiet = STORE_ERASE_QUIET_US;
    return motion_is_idle(&s->motion) && !s->tx.sending && !s->tx.waiting &&
           ring->written == ring->read && now - ring->heard_us >= quiet &&
           now - s->tx.ended_us >= quiet && save_policy_may_retry(&s->saver, &s->store, now);
}

/* The spare page's erase: 20-40 ms with the CPU stalled, the output
 * released. The pass after it (after_erase) resumes the control loop on a
 * fresh schedule (these ticks are not dropped ones), and carries out the
 * frames that arrived meanwhile without answering them: an answer that
 * late could fall in another servo's slot. */
static void erase_spare(struct servo *s, uint32_t now)
{
    s->erase_from = s->hal->rx->written;
    bool ok;
    if (config_store_spare_dirty(&s->store)) {
        ok = config_store_erase_spare(&s->store);
        save_policy_outcome(&s->saver, ok, now);
        s->saver.awaits_erase = (uint8_t)(s->saver.awaits_erase && !ok);
    } else {
        ok = fault_log_erase_spare(&s->faults);
        save_policy_outcome(&s->saver, ok, now); /* its retry wait, shared */
    }
    if (!ok) {
        s->regs.status.status |= STATUS_COMMAND_ERROR;
    }
    s->erase_passed = 1;
}

/* Once a control tick: counts operating time and erases the spare page
 * when that costs nothing. */
SERVO_JOB void servo_tend_store(struct servo *s, uint32_t now)
{
    save_policy_count_time(&s->saver, now);
    if ((config_store_spare_dirty(&s->store) || fault_log_spare_dirty(&s->faults)) &&
        erase_may_stall(s, now)) {
        erase_spare(s, now);
    } else {
        fault_log_step(&s->faults); /* a write block a tick: 70 us at most */
    }
    report_store(s);
}
