/* Motion commands as they arrive: run at once, queued behind a running one
 * (control response on) or buffered between BeginAsync and EndAsync; and
 * the answers owed when a queued command finishes. */
#include <stddef.h>

#include "motion/motion_internal.h"
#include "hal/size_first.h"

/* Push and pop: on the M0 called, not inlined at each of their two
 * callers, for its flash (a command is not timed). */
SIZE_FIRST_CALLED static bool queue_push(struct motion_queue *q, const struct motion_command *cmd)
{
    if (q->count >= MOTION_QUEUE_DEPTH) {
        return false;
    }
    q->slots[(q->head + q->count) % MOTION_QUEUE_DEPTH] = *cmd;
    q->count++;
    return true;
}

SIZE_FIRST_CALLED static const struct motion_command *queue_pop(struct motion_queue *q)
{
    if (q->count == 0u) {
        return NULL;
    }
    const struct motion_command *cmd = &q->slots[q->head];
    q->head = (uint8_t)((q->head + 1u) % MOTION_QUEUE_DEPTH);
    q->count--;
    return cmd;
}

/* Damping and stop act at once and drop what waits; other commands queue
 * behind a running one while control response is on. */
static enum motion_submit_result dispatch_command(struct motion *m, const struct motion_command *cmd)
{
    bool immediate = cmd->kind == MOTION_DAMPING || cmd->kind == MOTION_STOP;
    if (immediate) {
        m->queue.count = 0;
    } else if (m->regs->user.control_response && m->running) {
        return queue_push(&m->queue, cmd) ? MOTION_ACCEPTED : MOTION_QUEUE_FULL;
    }
    motion_run(m, cmd);
    return MOTION_ACCEPTED;
}

/* A refused command is not counted: it must not clear what the bus
 * watchdog did (safety_after_frame). Nor are commands for a block that
 * motion_stop cut short: they were sent for a plan that is gone, and run
 * nothing until the next BeginAsync (or EndAsync). */
enum motion_submit_result motion_submit(struct motion *m, const struct motion_command *cmd)
{
    if (m->inhibit || m->async_open == ASYNC_CUT) {
        return MOTION_REFUSED;
    }
    m->commands++;
    if (m->async_open) {
        return queue_push(&m->async, cmd) ? MOTION_ACCEPTED : MOTION_QUEUE_FULL;
    }
    return dispatch_command(m, cmd);
}

void motion_stop(struct motion *m, uint8_t method)
{
    const struct motion_command stop = {.kind = MOTION_STOP, .method = method};
    m->queue.count = 0;
    m->async_open = m->async_open != 0u ? ASYNC_CUT : 0u;
    m->async.count = 0;
    motion_run(m, &stop);
}

void motion_begin_async(struct motion *m)
{
    m->async_open = ASYNC_OPEN;
    m->async.count = 0;
    m->async.head = 0;
}

void motion_end_async(struct motion *m, bool cancel)
{
    m->async_open = 0;
    const struct motion_command *cmd;
    while ((cmd = queue_pop(&m->async)) != NULL) {
        if (!cancel) {
            (void)dispatch_command(m, cmd); /* overflow here drops, as on the wire */
        }
    }
}

bool motion_is_idle(const struct motion *m)
{
    return m->mode == MODE_RELEASED && !motion_is_moving(m) && m->queue.count == 0u &&
           m->async.count == 0u;
}

uint8_t motion_take_finished(struct motion *m)
{
    if (m->answers_count == 0u) {
        return 0;
    }
    uint8_t packet = m->answers[0];
    for (uint8_t i = 1; i < m->answers_count; i++) {
        m->answers[i - 1u] = m->answers[i];
    }
    m->answers_count--;
    return packet;
}

void motion_finish(struct motion *m)
{
    m->running = 0;
    if (m->answer_packet != 0u && m->answers_count < MOTION_ANSWERS_DEPTH) {
        m->answers[m->answers_count++] = m->answer_packet;
    }
    m->answer_packet = 0;
    if (m->end == END_RELEASE) {
        motion_coast(m);
    }
    const struct motion_command *next = queue_pop(&m->queue);
    if (next != NULL) {
        motion_run(m, next);
    }
}
