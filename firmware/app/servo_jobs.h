/* The servo core's jobs beside its main loop (servo.c): bus turn-taking
 * (servo_turns.c) and the store's upkeep (servo_store.c). Internal to
 * firmware/app. */
#ifndef APP_SERVO_JOBS_H
#define APP_SERVO_JOBS_H

#include <stdbool.h>
#include <stdint.h>

#include "app/servo_state.h"

/* The MCU images compile firmware/app's main loop and its jobs as one
 * translation unit (firmware/CMakeLists.txt, SERVO_APP_ONE_UNIT): there the
 * jobs are static, inlined into servo_poll as when they shared a file, so
 * the split costs no flash. */
#ifdef SERVO_APP_ONE_UNIT
#define SERVO_JOB static
#else
#define SERVO_JOB
#endif

/* What two places call, as one copy on the Cortex-M0, whose flash is full
 * (a call more on the answer's path); inlined elsewhere. */
#if defined(__ARM_ARCH_6M__)
#define SERVO_ONE_COPY __attribute__((noinline))
#else
#define SERVO_ONE_COPY inline __attribute__((always_inline))
#endif

/* s->tx.frame holds the response, sealed: it goes out now (wait 0) or after wait
 * other servos' responses (Sync Monitor). */
SERVO_JOB void servo_queue_response(struct servo *s, uint8_t wait, uint32_t responses_base, uint32_t now);
/* A queued response waits for its Sync Monitor turn: once a pass. */
SERVO_JOB void servo_wait_for_turn(struct servo *s, uint32_t now);
/* A finished move's answer, in this ID's slot of a quiet line. */
SERVO_JOB void servo_answer_finished_move(struct servo *s, uint32_t now);

/* The dispatcher's persist hook (ctx: the servo). */
SERVO_JOB bool servo_persist_config(void *ctx, const struct user_config *cfg);
/* Once a control tick: operating time, the spare page's erase when that
 * costs nothing, ReadStore's register group. */
SERVO_JOB void servo_tend_store(struct servo *s, uint32_t now);

#endif
