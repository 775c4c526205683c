/* The store's upkeep (servo_store.c): the config store and the fault
 * history's records in flash, their save policy, saves for the dispatcher,
 * the spare page's erase when it costs nothing, operating time and
 * ReadStore's register group. Its state is its own (struct servo_store);
 * what it reads of the port, the motion and the bus's turns is handed in. */
#ifndef APP_SERVO_STORE_H
#define APP_SERVO_STORE_H

#include <stdbool.h>
#include <stdint.h>

#include "app/servo_turns.h"
#include "hal/hal_port.h"
#include "motion/motion.h"
#include "registers/registers.h"
#include "storage/config_store.h"
#include "storage/fault_log.h"
#include "storage/save_policy.h"

/* The other flash page is erased, a 20-40 ms CPU stall (DS5319, tERASE),
 * only at power-up and while the output is released (nothing held against
 * a load) and the line has been quiet for STORE_ERASE_QUIET_US; never on a
 * host's schedule. A change that needs it meanwhile is refused with its
 * reason (docs/decisions.md, "The config store"). The DMA goes on writing
 * through the stall, but the laps it completes then cannot be counted: at
 * a baud rate whose STORE_ERASE_MAX_US of bytes the ring cannot hold (the
 * Cortex-M0 board above 115200), what came in is dropped and counted as
 * lost once the ring has wrapped (servo.c, after_erase). */
#define STORE_ERASE_QUIET_US 100000u
#define STORE_ERASE_MAX_US 40000u

/* The job's own state; the config store and the fault history (whose
 * entries come from the safety parts, fault_log_add) are handed in. */
struct servo_store {
    struct save_policy saver;
    uint32_t erase_from;        /* the ring's written count as the last erase began */
};

/* What a tick's upkeep did: a page erase stalls the CPU (the main loop
 * resumes on a fresh schedule, servo.c's after_erase). */
enum store_tended {
    STORE_TENDED = 0,
    STORE_ERASED = 1,
    STORE_ERASE_FAILED = 2,
};

/* At power-up: the config store's load into user, a store older firmware
 * wrote rewritten, the spare page erased ahead, the save policy. */
void store_start(struct servo_store *j, struct config_store *config,
                 const struct hal_flash *flash, struct user_config *user, uint32_t now);
/* At power-up, after store_start: the fault history's load (the operating
 * time goes on from its latest record too) and its spare page's erase;
 * false when that failed. */
bool store_load_faults(struct servo_store *j, struct fault_log *faults,
                       const struct hal_flash *flash);
/* The dispatcher's persist hook's work: cfg to flash now, or refused;
 * ReadStore's flags (h) say why. */
bool store_persist(struct servo_store *j, struct config_store *config,
                   struct store_health *h, const struct user_config *cfg, uint32_t now);
/* Once a control tick: operating time, the spare page's erase when that
 * costs nothing (the motion idle, the line and the bus's turns quiet),
 * a block of the fault history, ReadStore's register group (h; its two
 * counters of the main loop's, the caller's). */
enum store_tended store_tend(struct servo_store *j, struct config_store *config,
                             struct fault_log *faults, struct store_health *h,
                             const struct hal_rx_ring *ring, const struct motion *m,
                             const struct servo_tx *tx, uint32_t now);
/* ClearFaults: the history's marker. */
bool store_clear_faults(const struct servo_store *j, struct fault_log *faults);

#endif
