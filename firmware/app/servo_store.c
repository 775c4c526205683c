/* The store's upkeep (servo_store.h): saves for the dispatcher, the spare
 * page's erase when it costs nothing, operating time and ReadStore's
 * register group. */
#include "app/servo_store.h"

#include <stdbool.h>

#include "hal/size_first.h"

void store_start(struct servo_store *j, struct config_store *config,
                 const struct hal_flash *flash, struct user_config *user, uint32_t now)
{
    config_store_load(config, flash, user);
    /* A store older firmware wrote (formats 1 and 2) is rewritten in format
     * 3, the one the bootloader reads the ID and baud rate from. Then the spare
     * page is erased ahead, before the control loop runs: saves need no
     * erase until the page in use is full. A failure of either stays in the
     * store (ReadStore reports it, the next save tries again): at power-up
     * nobody waits for an answer. */
    bool rewritten = !config->legacy ||
                     config_store_save(config, user, config->op_seconds) == CONFIG_SAVED;
    bool spare_ready = !config_store_spare_dirty(config) || config_store_erase_spare(config);
    (void)rewritten;
    (void)spare_ready;
    save_policy_init(&j->saver, config, now);
}

bool store_load_faults(struct servo_store *j, struct fault_log *faults,
                       const struct hal_flash *flash)
{
    /* The operating time goes on from the latest record in either store
     * (the config store's saves, the faults' records): no write of its own. */
    save_policy_carry_op_seconds(&j->saver, fault_log_load(faults, flash));
    return !fault_log_spare_dirty(faults) || fault_log_erase_spare(faults);
}

/* ReadStore's flags (enum store_flag). On the M0 called (a tick's report and a
 * save's), not inlined twice. */
SIZE_FIRST_CALLED static uint8_t store_flags(const struct servo_store *j,
                                             const struct config_store *config)
{
    return (uint8_t)((config->failed ? STORE_FAILED : 0u) |
                     (j->saver.over_budget ? STORE_OVER_BUDGET : 0u) |
                     (j->saver.awaits_erase ? STORE_AWAITS_ERASE : 0u));
}

/* ReadStore's register group, on a change or a new second only: it
 * divides. */
static void report_store(const struct servo_store *j, const struct config_store *config,
                         const struct fault_log *faults, struct store_health *h)
{
    uint8_t flags = store_flags(j, config);
    uint32_t op_seconds = save_policy_op_seconds(&j->saver);
    h->fault_count = faults->shown_count;
    h->faults_not_logged = faults->not_logged;
    if (flags == h->flags && op_seconds == h->op_seconds && h->rated_cycles != 0u &&
        config->sequence == h->records && config->write_failures == h->failures) {
        return;
    }
    h->flags = flags;
    h->records = config->sequence;
    h->page_erases = config_store_page_erases(config);
    h->rated_cycles = FLASH_RATED_CYCLES;
    h->budget = save_policy_budget(&j->saver);
    h->op_seconds = op_seconds;
    h->failures = config->write_failures;
}

/* A changed user or drive area goes to flash before the write is
 * answered, all its write blocks at once (36 half-words, 1.4-2.5 ms on the
 * STM32F1; the ticks catch up after, the DMA ring holds what arrives). A
 * change that cannot be made durable now is refused, and ReadStore says
 * why: past the wear budget, no erased slot until the output is released,
 * or the flash refused. */
static bool save_now(struct servo_store *j, struct config_store *config,
                     const struct user_config *cfg, uint32_t now)
{
    j->saver.over_budget = !save_policy_allows(&j->saver, config);
    if (j->saver.over_budget) {
        return false;
    }
    enum config_save_result r =
        config_store_begin(config, cfg, save_policy_op_seconds(&j->saver));
    if (r == CONFIG_NEEDS_ERASE) {
        j->saver.awaits_erase = 1;
        return false;
    }
    while (r == CONFIG_STARTED || r == CONFIG_BUSY) {
        r = config_store_step(config);
    }
    bool ok = r != CONFIG_WRITE_FAILED;
    save_policy_outcome(&j->saver, ok, now);
    return ok;
}

bool store_persist(struct servo_store *j, struct config_store *config,
                   struct store_health *h, const struct user_config *cfg, uint32_t now)
{
    bool ok = save_now(j, config, cfg, now);
    /* A ReadStore right after the answer says why; the rest of its group
     * follows at the next tick (report_store). */
    h->flags = store_flags(j, config);
    return ok;
}

/* A page erase stalls the CPU for 20-40 ms: bytes wait in the DMA ring,
 * ticks do not run. Only while the output is released and the line is
 * quiet (STORE_ERASE_*). */
static bool erase_may_stall(const struct servo_store *j, const struct config_store *config,
                            const struct hal_rx_ring *ring,
                            const struct motion *m, const struct servo_tx *tx, uint32_t now)
{
    const uint32_t quiet = STORE_ERASE_QUIET_US;
    return motion_is_idle(m) && turns_quiet_for(tx, now, quiet) && ring->written == ring->read &&
           now - ring->heard_us >= quiet && save_policy_may_retry(&j->saver, config, now);
}

/* The spare page's erase: 20-40 ms with the CPU stalled, the output
 * released. The pass after it (servo.c's after_erase) resumes the control
 * loop on a fresh schedule (these ticks are not dropped ones), and carries
 * out the frames that arrived meanwhile without answering them: an answer
 * that late could fall in another servo's slot. */
static enum store_tended erase_spare(struct servo_store *j, struct config_store *config,
                                     struct fault_log *faults, const struct hal_rx_ring *ring,
                                     uint32_t now)
{
    j->erase_from = ring->written;
    bool ok;
    if (config_store_spare_dirty(config)) {
        ok = config_store_erase_spare(config);
        save_policy_outcome(&j->saver, ok, now);
        j->saver.awaits_erase = (uint8_t)(j->saver.awaits_erase && !ok);
    } else {
        ok = fault_log_erase_spare(faults);
        save_policy_outcome(&j->saver, ok, now); /* its retry wait, shared */
    }
    return ok ? STORE_ERASED : STORE_ERASE_FAILED;
}

enum store_tended store_tend(struct servo_store *j, struct config_store *config,
                             struct fault_log *faults, struct store_health *h,
                             const struct hal_rx_ring *ring, const struct motion *m,
                             const struct servo_tx *tx, uint32_t now)
{
    save_policy_count_time(&j->saver, now);
    enum store_tended done = STORE_TENDED;
    if ((config_store_spare_dirty(config) || fault_log_spare_dirty(faults)) &&
        erase_may_stall(j, config, ring, m, tx, now)) {
        done = erase_spare(j, config, faults, ring, now);
    } else {
        fault_log_step(faults); /* a write block a tick: 70 us at most */
    }
    report_store(j, config, faults, h);
    return done;
}

/* ClearFaults: the history's marker. Not through the safety parts' entry
 * with the readings: they would take the M0's answer past its 30 us
 * (target benchmark, answer_clear_faults). */
bool store_clear_faults(const struct servo_store *j, struct fault_log *faults)
{
    struct fault_entry marker; /* field by field: an initialiser is a memset call on the M0 */
    marker.number = 0;
    marker.op_seconds = save_policy_op_seconds(&j->saver);
    marker.angle_decideg = 0;
    marker.voltage_mv = marker.current_ma = marker.power_mw = 0;
    marker.winding_decic = marker.case_decic = 0;
    marker.what = FAULT_CLEARED;
    return fault_log_add(faults, &marker);
}
