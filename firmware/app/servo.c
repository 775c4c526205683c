#include "app/servo.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "app/identity.h"
#include "app/servo_safety.h"
#include "app/servo_store.h"
#include "app/servo_turns.h"
#include "protocol/wire.h"
#include "registers/data_table.h"

static uint32_t idle_timeout_us(const struct servo *s, uint32_t baud)
{
    return frame_rx_port_idle_us(frame_rx_idle_us(baud), s->hal->rx_gap_tolerance_us);
}

static void apply_link_settings(struct servo *s)
{
    s->active_id = s->regs.user.servo_id;
    uint32_t baud = baud_rate_of_index(s->regs.user.baud_index);
    if (s->active_baud_index != s->regs.user.baud_index) {
        s->active_baud_index = s->regs.user.baud_index;
        s->hal->bus.set_baud(s->hal->ctx, baud);
        s->rx_idle_us = idle_timeout_us(s, baud);
    }
    /* Divides: on a change of link settings only. */
    uint32_t byte_us = baud != 0u ? (10000000u + baud - 1u) / baud : 0u;
    s->ring_covers_erase = hal_rx_ring_size(s->hal->rx) * byte_us >= STORE_ERASE_MAX_US;
    turns_set_link(&s->tx, s->active_id, byte_us);
    s->turn_guard_bytes = (uint8_t)(byte_us != 0u ? s->hal->tick_and_pass_us / byte_us : 0u);
}

/* The dispatcher's persist hook (ctx: the servo): the store's job. */
static bool persist_config(void *ctx, const struct user_config *cfg)
{
    struct servo *s = ctx;
    return store_persist(&s->saving, &s->store, &s->regs.store, cfg, s->hal->bus.now_us(s->hal->ctx));
}

/* ClearFaults (ctx: the servo): the history's marker. */
static bool clear_faults(void *ctx)
{
    struct servo *s = ctx;
    return store_clear_faults(&s->saving, &s->faults);
}

void servo_init(struct servo *s, const struct hal_port *hal)
{
    *s = (struct servo){.hal = hal};
    store_start(&s->saving, &s->store, hal->flash, &s->regs.user, hal->bus.now_us(hal->ctx));
    firmware_area_factory(&s->regs.firmware);
    s->sensors.current_zero = s->regs.user.current_zero_counts;
    s->regs.status.model = SERVO_MODEL;
    uint16_t image_version = hal->image_version != NULL ? hal->image_version(hal->ctx) : 0u;
    s->regs.status.firmware_version = image_version != 0u ? image_version : FIRMWARE_VERSION;
    s->regs.status.serial_number = hal->serial_number(hal->ctx);
    protection_init(&s->protection);
    motion_init(&s->motion, &s->regs, hal);
    s->next_tick_us = hal->bus.now_us(hal->ctx) + CONTROL_TICK_US;
    tick_scheduled(s);
    frame_rx_init(&s->rx, &s->active_id);
    s->rx_idle_us = idle_timeout_us(s, 0);
    dispatcher_init(&s->dispatcher, &s->regs, &s->motion, &s->active_id);
    s->dispatcher.bootloader_present = hal->enter_bootloader != NULL;
    s->dispatcher.board = hal->board;
    s->dispatcher.persist = persist_config;
    s->dispatcher.persist_ctx = s;
    if (!store_load_faults(&s->saving, &s->faults, hal->fault_flash)) {
        s->regs.status.status |= STATUS_COMMAND_ERROR; /* nobody waits at power-up */
    }
    /* Faults go into the history, with the store's operating time. */
    safety_init(&s->safety, &s->regs, &s->protection,
                (struct safety_log){.faults = &s->faults, .clock = &s->saving.saver}, hal);
    s->dispatcher.read_fault = fault_log_read;
    s->dispatcher.read_fault_ctx = &s->faults;
    s->dispatcher.clear_faults = clear_faults;
    s->dispatcher.faults_ctx = s;
    s->active_baud_index = 0; /* forces the first apply to set the UART */
    apply_link_settings(s);
}

/* Status bit 0 follows the motion: after each tick and each command. */
static void show_executing(struct servo *s)
{
    uint8_t status = (uint8_t)(s->regs.status.status & ~STATUS_EXECUTING);
    s->regs.status.status =
        motion_is_executing(&s->motion) ? (uint8_t)(status | STATUS_EXECUTING) : status;
}

/* A Sync Monitor that lists this servo first: its answer is certain (the
 * dispatcher answers every such record: a Monitor record of one byte in a
 * consistent SyncCommand), so the pass that frames the checksum byte
 * writes its header and ID and hands the frame to the UART first, then
 * builds the rest behind the bytes going out. The DMA takes the content's
 * second byte four byte times after the start; the build takes less than
 * three on the Cortex-M0 (docs/sleep.md, "The first answer"), and every
 * byte it writes at the front is the value already there (dispatcher.c
 * leaves a sync record's answer length to its handler). The M3 answers
 * within two byte times built first, and leaves it out. */
#if !defined(__arm__) || defined(__ARM_ARCH_6M__)
#define SERVO_SENDS_AHEAD 1
enum { MONITOR_ANSWER_LENGTH = 16 };
static __attribute__((noinline)) bool send_ahead(struct servo *s, const struct rx_frame *f,
                                                 uint32_t now)
{
    /* Called for a record index 0: a SyncCommand's, its header consistent
     * (the framer looks for records only then). */
    if (f->content[0] != PKT_MONITOR || f->content[1] != 1u) {
        return false;
    }
    struct response *r = &s->tx.frame;
    r->words[0] = WIRE_RESPONSE_HDR0 | (uint32_t)WIRE_RESPONSE_HDR1 << 8 |
                  (uint32_t)PKT_MONITOR << 16 | (uint32_t)MONITOR_ANSWER_LENGTH << 24;
    r->content[0] = f->content[3]; /* the record: this servo's ID */
    turns_queue(&s->tx, s->hal, &s->rx, 0, f->responses_seen, now);
    dispatch(&s->dispatcher, f, r, &s->dispatched);
    s->dispatched.answer = 0; /* on its way already */
    return true;
}
#else
#define SERVO_SENDS_AHEAD 0
#define send_ahead(s, f, now) false
#endif

/* late: the request arrived while a page erase stalled the CPU (after_erase).
 * It is carried out, but its answer, tens of milliseconds late, could fall
 * in another servo's slot: it is not sent, and ReadStore counts it. */
static SERVO_ONE_COPY void handle_next_frame(struct servo *s, uint32_t now, bool late)
{
    const struct rx_frame *frame = &s->rx.slots[s->rx.tail]; /* the callers know there is one */
    struct dispatch_result *result = &s->dispatched;
    if (!SERVO_SENDS_AHEAD || frame->sync_index != 0u || late || !send_ahead(s, frame, now)) {
        dispatch(&s->dispatcher, frame, &s->tx.frame, result);
    }
    uint32_t responses_base = frame->responses_seen;
    frame_rx_release(&s->rx);
    show_executing(s);
    if (s->safety.watchdog.fired) {
        /* a motion command clears what the watchdog did */
        safety_after_frame(&s->safety, &s->regs, s->motion.commands);
    }
    if (result->config_changed) {
        s->link_settings_pending = 1;
        s->sensors.current_zero = s->regs.user.current_zero_counts; /* item 91 */
    }
    s->enter_bootloader |= result->enter_bootloader;
    if (result->answer && late) {
        s->answers_dropped++;
    } else if (result->answer) {
        turns_queue(&s->tx, s->hal, &s->rx, result->wait_responses, responses_base, now);
    }
}

/* Sensors to the status area (IDs 1-4), monitors to what the output may
 * do; returns status bits 2-7. */
static uint8_t sense_and_protect(struct servo *s)
{
    struct sensor_raw raw;
    s->hal->motor.read_sensors(s->hal->ctx, &raw);
    enum sense_slot slot = sensors_update(&s->sensors, s->hal->calibration, &raw);
    const struct sensor_readings *now = &s->sensors.out;
    /* IDs 1-4 lie as the readings do: one copy (ldrd/strd on the M3). */
    memcpy((uint8_t *)&s->regs.status + offsetof(struct status_area, voltage_mv), now, sizeof *now);
    struct protection *p = &s->protection;
    uint8_t bits = (uint8_t)(protection_update(p, &s->regs.user, now, slot) |
                             protection_stall(p, &s->regs.user, motion_output_at_limit(&s->motion),
                                              s->motion.measured_velocity_q8, s->motion.commands));
    if (p->act.release_now) {
        motion_release(&s->motion);
    }
    if (p->act_changes != s->guard_seen) {
        s->guard_seen = p->act_changes;
        safety_guard(&s->safety, &s->regs, &s->motion, p, bits);
    }
    return bits;
}

/* The status byte once a tick: the monitors' bits, the motion's (bit 0),
 * the dispatcher's (bit 1) as it stands. */
void servo_control_tick(struct servo *s)
{
    uint8_t bits = sense_and_protect(s);
    motion_tick(&s->motion);
    struct status_area *st = &s->regs.status;
    st->status = (uint8_t)((st->status & STATUS_COMMAND_ERROR) | bits |
                           (motion_is_executing(&s->motion) ? STATUS_EXECUTING : 0u));
}

/* The control loop runs from the main loop, so commands and ticks never
 * interleave. A pass runs every tick that is due, up to SERVO_MAX_CATCH_UP; a
 * main loop later than that (a flash erase) drops the rest rather than
 * racing through them. */
static bool run_control_tick(struct servo *s, uint32_t now)
{
    if ((int32_t)(now - s->tick_due_us) < 0) {
        return false; /* most passes */
    }
    /* A request for this servo about to end: a tick now (with the pass
     * after it) could hold back its answer, or the answer's preparation,
     * beyond two byte times. The tick waits for the request's end, two byte
     * times and two a tick and a pass take at most (the schedule stays:
     * the tick after is due on time). */
    if (frame_rx_kept_ends_within(&s->rx, 2u * s->turn_guard_bytes + 2u)) {
        return false;
    }
    unsigned n = 0;
    for (; (int32_t)(now - s->next_tick_us) >= 0; n++) {
        if (n == SERVO_MAX_CATCH_UP) {
            s->ticks_dropped += (uint32_t)(now - s->next_tick_us) / CONTROL_TICK_US + 1u;
            s->next_tick_us = now + CONTROL_TICK_US;
            tick_scheduled(s);
            return true;
        }
        servo_control_tick(s);
        s->next_tick_us += CONTROL_TICK_US;
    }
    tick_scheduled(s);
    return true;
}

/* The ring to the framer, a line silent for the idle timeout dropping a
 * partial frame: a pass's, and after an erase (one copy on the M0). */
static SERVO_ONE_COPY void frame_ring(struct servo *s, uint32_t now)
{
    frame_rx_receive(&s->rx, s->hal->rx, &s->rx_lost, now, s->rx_idle_us);
}

/* What the port has received since the last pass, to the framer. */
static void receive(struct servo *s, uint32_t now)
{
    hal_rx_sync(s->hal, now);
    frame_ring(s, now);
}

/* The pass after a page erase: the control loop resumes on a fresh
 * schedule (released, it has nothing to catch up on), and what arrived
 * during the erase is carried out now, none of it answered
 * (handle_next_frame). The ring may hold more frames than the framer's
 * queue: they are framed a queue at a time. Kept out of servo_poll, which
 * then checks for it once a pass. */
__attribute__((noinline, cold)) static void after_erase(struct servo *s, uint32_t now)
{
    s->erase_passed = 0;
    s->next_tick_us = now + CONTROL_TICK_US;
    tick_scheduled(s);
    struct hal_rx_ring *ring = s->hal->rx;
    hal_rx_sync(s->hal, now);
    uint32_t erase_from = s->saving.erase_from;
    uint32_t came = ring->written - erase_from;
    if (!s->ring_covers_erase && (erase_from & ring->mask) + came > ring->mask) {
        /* The ring wrapped during the stall at a rate it cannot cover: how
         * many laps, nobody counted. All of it is dropped, and counted. */
        s->rx_lost += came;
        ring->read = ring->written;
        frame_rx_line_idle(&s->rx);
        return;
    }
    for (;;) {
        frame_ring(s, now);
        for (uint8_t stale = frame_rx_pending(&s->rx); stale != 0u; stale--) {
            handle_next_frame(s, now, true);
        }
        if (ring->read == ring->written) {
            return;
        }
    }
}

/* UpdateEnter, its answer gone: every accepted change is in flash already. */
static void restart_into_bootloader(struct servo *s)
{
    s->enter_bootloader = 0;
    hal_enter_bootloader(s->hal, s->active_id, s->active_baud_index);
}

/* The jobs' upkeep, once a control tick: the monitors', then the store's
 * (a page erase: after_erase takes over the next pass). */
__attribute__((noinline)) static void tend_jobs(struct servo *s, uint32_t now)
{
    safety_tend(&s->safety, &s->regs, &s->motion, s->dispatcher.heard);
    s->regs.store.answers_dropped = s->answers_dropped;
    s->regs.store.bytes_lost = s->rx_lost;
    enum store_tended done = store_tend(&s->saving, &s->store, &s->faults, &s->regs.store,
                                        s->hal->rx, &s->motion, &s->tx, now);
    s->erase_passed = (uint8_t)(done != STORE_TENDED);
    if (done == STORE_ERASE_FAILED) {
        s->regs.status.status |= STATUS_COMMAND_ERROR;
    }
}

void servo_poll(struct servo *s)
{
    /* One reading of the clock per pass: the ticks due by then run now. */
    uint32_t now = s->hal->bus.now_us(s->hal->ctx);
    s->polled_us = now;
    if (s->erase_passed) {
        /* Framing what came during the erase takes a while on the M0 (2 ms
         * for 500 bytes): this pass's clock reading is stale after it, and
         * would stamp new bytes as heard that long ago, so that the next
         * pass took the line for idle mid-frame. The next pass reads anew. */
        after_erase(s, now);
        return;
    }
    bool ticked = run_control_tick(s, now);
    if (s->tx.sending && s->hal->bus.tx_done(s->hal->ctx)) {
        turns_sent(&s->tx, now);
        if (s->enter_bootloader) { /* UpdateEnter's answer has left */
            restart_into_bootloader(s);
            return;
        }
    }
    /* A new ID or baud rate takes effect once the response has left, and
     * before the next request is read. */
    if (s->link_settings_pending && !s->tx.sending && !s->tx.waiting) {
        s->link_settings_pending = 0;
        if (s->active_id != s->regs.user.servo_id ||
            s->active_baud_index != s->regs.user.baud_index) {
            apply_link_settings(s);
        }
    }
    receive(s, now);
    if (ticked) {
        tend_jobs(s, now);
    }
    if (s->tx.sending) {
        return; /* half duplex: nothing else goes out meanwhile */
    }
    if (s->tx.waiting) {
        if (s->rx.stats.requests_seen == s->tx.requests_base) {
            s->tick_due_us =
                s->next_tick_us + turns_wait(&s->tx, s->hal, &s->rx, s->turn_guard_bytes, now);
            return;
        }
        /* A new request (to anyone) while this servo waits for its Sync
         * Monitor turn: the host has given up on that round, and is owed
         * this answer instead. */
        turns_abandon(&s->tx);
        s->sync_turns_abandoned++;
    }
    /* Requests first: the host waits for their answers, while a finished
     * move's answer waits for a quiet line anyway. */
    if (frame_rx_peek(&s->rx) != NULL) {
        handle_next_frame(s, now, false);
    }
    if (!s->tx.sending && !s->tx.waiting) {
        turns_answer_finished_move(&s->tx, s->hal, &s->motion, s->active_id, now);
    }
}

/* The interrupts that end a sleep: the control tick (SysTick), a line gone
 * idle after bytes (the bus USART's IDLE), a transmission's end, a lap of
 * the receive DMA. The DMA takes a request's bytes without waking the CPU,
 * so the loop stays awake while the line is in use (heard within
 * SERVO_AWAKE_AFTER_LINE_US): it frames a request as its bytes land. After
 * a longer quiet a request is framed once the line has been idle for a
 * byte time after it (or at the next tick, when another frame follows at
 * once). What is timed finer than the tick (a Sync Monitor turn, the
 * finished move's slot, the link settings after an answer) keeps the loop
 * awake too. */
/* Nothing for a pass to do before an interrupt comes, the line's bytes
 * apart; *now: the clock's reading, the ring brought up to date. */
static inline __attribute__((always_inline)) bool nothing_due(struct servo *s, uint32_t *now)
{
    if (s->erase_passed || s->tx.waiting || s->link_settings_pending || s->enter_bootloader ||
        frame_rx_pending(&s->rx) != 0u ||
        motion_has_finished(&s->motion)) {
        return false;
    }
    if (s->tx.sending && s->hal->bus.tx_done(s->hal->ctx)) {
        return false;
    }
    *now = s->hal->bus.now_us(s->hal->ctx);
    if ((int32_t)(*now - s->next_tick_us) >= 0) {
        return false;
    }
    hal_rx_sync(s->hal, *now);
    return true;
}

bool servo_may_sleep(struct servo *s)
{
    /* The line in use as the pass just run saw it: awake, without reading
     * the clock and the ring again (a loop that polls goes round sooner). */
    if (s->polled_us - s->hal->rx->heard_us < SERVO_AWAKE_AFTER_LINE_US) {
        return false;
    }
    /* Bytes not yet framed were heard just now: they keep it awake too
     * (a full queue's wait in the ring, its frames pending). */
    uint32_t now;
    return nothing_due(s, &now) && now - s->hal->rx->heard_us >= SERVO_AWAKE_AFTER_LINE_US;
}

bool servo_awaits_bytes(struct servo *s)
{
    uint32_t now;
    return nothing_due(s, &now) && s->hal->rx->written == s->hal->rx->read;
}
