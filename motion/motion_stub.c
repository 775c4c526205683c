/* Stand-in for the motion layer until the planner lands: every move reaches
 * its target at once. Replaced, not extended, by the planner. */
#include <stddef.h>

#include "motion/motion.h"

enum { DECIDEG_PER_TURN = 3600 };

void motion_init(struct motion *m, const struct user_config *cfg)
{
    (void)cfg;
    *m = (struct motion){0};
}

static void run(struct motion *m, const struct motion_command *cmd)
{
    switch (cmd->kind) {
    case MOTION_ANGLE:
        m->position_decideg = cmd->angle_decideg;
        m->controlled = 1;
        break;
    case MOTION_WHEEL:
        m->controlled = (cmd->method & 0x7Fu) != 0u;
        break;
    default:
        m->controlled = 0;
        break;
    }
    if (cmd->answer_when_done) {
        m->finished_packet = cmd->packet;
    }
}

enum motion_submit_result motion_submit(struct motion *m, const struct motion_command *cmd)
{
    if (m->async_open) {
        if (m->async_count >= MOTION_ASYNC_MAX) {
            return MOTION_QUEUE_FULL;
        }
        m->async_buffer[m->async_count++] = *cmd;
        return MOTION_ACCEPTED;
    }
    if (cmd->answer_when_done && m->finished_packet != 0u) {
        return MOTION_QUEUE_FULL;
    }
    run(m, cmd);
    return MOTION_ACCEPTED;
}

bool motion_is_released(const struct motion *m)
{
    return !m->controlled;
}

void motion_read_angle(const struct motion *m, struct motion_angle *out)
{
    int32_t p = m->position_decideg;
    out->multi_turn_decideg = p;
    out->turns = (int16_t)(p / DECIDEG_PER_TURN);
    int32_t single = p % DECIDEG_PER_TURN;
    if (single > DECIDEG_PER_TURN / 2) {
        single -= DECIDEG_PER_TURN;
    } else if (single < -DECIDEG_PER_TURN / 2) {
        single += DECIDEG_PER_TURN;
    }
    out->single_turn_decideg = (int16_t)single;
}

bool motion_reset_multi_turn(struct motion *m)
{
    if (m->controlled) {
        return false;
    }
    m->position_decideg %= DECIDEG_PER_TURN;
    return true;
}

bool motion_set_origin(struct motion *m)
{
    if (m->controlled) {
        return false;
    }
    m->position_decideg = 0;
    return true;
}

void motion_begin_async(struct motion *m)
{
    m->async_open = 1;
    m->async_count = 0;
}

void motion_end_async(struct motion *m, bool cancel)
{
    m->async_open = 0;
    for (uint8_t i = 0; !cancel && i < m->async_count; i++) {
        run(m, &m->async_buffer[i]);
    }
    m->async_count = 0;
}

uint8_t motion_take_finished(struct motion *m)
{
    uint8_t packet = m->finished_packet;
    m->finished_packet = 0;
    return packet;
}

bool motion_is_executing(const struct motion *m)
{
    (void)m;
    return false;
}
