/* Packets that command or read the motion layer: 7-19, 23, 24, 0x40, 0x45. They decode
 * the request into a struct motion_command and leave clamping, limits and
 * timing to the motion layer. */
#include <stddef.h>

#include "protocol/packet_codes.h"
#include "protocol/packet_table.h"
#include "protocol/wire.h"
#include "hal/size_first.h"
#include "registers/field_ranges.h"

/* StopOnControlMode's methods, as the schema ranges them. */
_Static_assert(STOP_RELEASE == FIELD_STOP_ON_CONTROL_MODE_METHOD_MIN &&
                   STOP_DAMPING == FIELD_STOP_ON_CONTROL_MODE_METHOD_MAX,
               "the stop methods are the schema's");

/* Ramps of the packets that carry none (8, 13): docs/protocol.md, "Moves". */
enum { DEFAULT_RAMP_MS = 20 };

/* The angle packets' fields after the ID: angle (2 bytes, 4 for a
 * multi-turn one), interval (2 bytes, 4 for a multi-turn angle) or
 * velocity (2), [acc, dec] (2 each), power (2). Each kind's three forms,
 * by their codes: plain, by interval (with ramps), by velocity (with
 * ramps); worked out from the code, no table. */
enum { FORM_PLAIN, FORM_INTERVAL, FORM_VELOCITY };
_Static_assert(PKT_MOVE_ANGLE_BY_VELOCITY == PKT_MOVE_ANGLE_BY_INTERVAL + 1 &&
                   PKT_MOVE_MULTI_TURN_BY_INTERVAL == PKT_MOVE_MULTI_TURN + FORM_INTERVAL &&
                   PKT_MOVE_MULTI_TURN_BY_VELOCITY == PKT_MOVE_MULTI_TURN + FORM_VELOCITY &&
                   PKT_MOVE_MULTI_TURN > PKT_MOVE_ANGLE_BY_VELOCITY &&
                   PKT_MOVE_ANGLE < PKT_MOVE_ANGLE_BY_INTERVAL,
               "the angle packets' codes in their forms' order");

/* On the M0 called, not inlined: four handlers' zeroing and stores in one copy. */
SIZE_FIRST_CALLED static struct motion_command command_for(const struct packet_call *c, uint8_t kind)
{
    return (struct motion_command){
        .packet = c->code,
        .kind = kind,
        .answer_when_done = c->answer_when_done,
    };
}

static enum packet_outcome submit(const struct packet_call *c, const struct motion_command *cmd)
{
    /* A full queue drops the command: no answer, command error. */
    return motion_submit(c->d->motion, cmd) == MOTION_ACCEPTED ? OUTCOME_DEFERRED
                                                              : OUTCOME_ERROR;
}

enum packet_outcome handle_move_angle(const struct packet_call *c, struct response *r)
{
    (void)r;
    uint8_t code = c->code; /* one of the six (the packet table's) */
    bool multi = code >= PKT_MOVE_MULTI_TURN;
    unsigned form = multi                    ? (unsigned)(code - PKT_MOVE_MULTI_TURN)
                    : code == PKT_MOVE_ANGLE ? FORM_PLAIN
                                             : (unsigned)(code - PKT_MOVE_ANGLE_BY_INTERVAL) + FORM_INTERVAL;
    const uint8_t *p = &c->content[1];
    struct motion_command cmd = command_for(c, MOTION_ANGLE);
    cmd.multi_turn = multi;
    cmd.angle_decideg = multi ? le_get_i32(p) : le_get_i16(p);
    p += multi ? 4 : 2;
    if (form == FORM_VELOCITY) {
        cmd.profile = PROFILE_VELOCITY;
        cmd.velocity_decideg_s = le_get_u16(p);
        p += 2;
    } else if (multi) {
        cmd.interval_ms = le_get_u32(p);
        p += 4;
    } else {
        cmd.interval_ms = le_get_u16(p);
        p += 2;
    }
    cmd.acc_ms = DEFAULT_RAMP_MS;
    cmd.dec_ms = DEFAULT_RAMP_MS;
    if (form != FORM_PLAIN) {
        cmd.acc_ms = le_get_u16(p);
        cmd.dec_ms = le_get_u16(p + 2);
        p += 4;
    }
    cmd.power_mw = le_get_u16(p);
    return submit(c, &cmd);
}

enum packet_outcome handle_move_wheel(const struct packet_call *c, struct response *r)
{
    (void)r;
    struct motion_command cmd = command_for(c, MOTION_WHEEL);
    cmd.method = c->content[1];
    cmd.wheel_speed_deg_s = le_get_u16(&c->content[2]);
    cmd.wheel_value = le_get_u16(&c->content[4]);
    return submit(c, &cmd);
}

enum packet_outcome handle_move_damping(const struct packet_call *c, struct response *r)
{
    struct motion_command cmd = command_for(c, MOTION_DAMPING);
    cmd.power_mw = le_get_u16(&c->content[1]);
    cmd.answer_when_done = 0; /* nothing to finish: answered at once */
    if (motion_submit(c->d->motion, &cmd) != MOTION_ACCEPTED) {
        return OUTCOME_ERROR;
    }
    return answer_result(r, true);
}

enum packet_outcome handle_stop(const struct packet_call *c, struct response *r)
{
    (void)r;
    struct motion_command cmd = command_for(c, MOTION_STOP);
    cmd.method = c->content[1];
    cmd.power_mw = le_get_u16(&c->content[2]);
    cmd.answer_when_done = 0;
    if (cmd.method < STOP_RELEASE || cmd.method > STOP_DAMPING) {
        return OUTCOME_ERROR;
    }
    return motion_submit(c->d->motion, &cmd) == MOTION_ACCEPTED ? OUTCOME_OK : OUTCOME_ERROR;
}

enum packet_outcome handle_stream_setpoint(const struct packet_call *c, struct response *r)
{
    (void)r;
    const struct motion_setpoint sp = {
        .angle_decideg = le_get_i32(&c->content[1]),
        .velocity_decideg_s = le_get_i16(&c->content[5]),
        .host_ms = le_get_u16(&c->content[7]),
    };
    return motion_stream(c->d->motion, &sp) == MOTION_ACCEPTED ? OUTCOME_OK : OUTCOME_ERROR;
}

enum packet_outcome handle_drive_duty(const struct packet_call *c, struct response *r)
{
    (void)r;
    int16_t duty = le_get_i16(&c->content[1]);
    uint16_t ms = le_get_u16(&c->content[3]);
    return motion_drive_duty(c->d->motion, duty, ms) == MOTION_ACCEPTED ? OUTCOME_OK : OUTCOME_ERROR;
}

enum packet_outcome handle_read_angle(const struct packet_call *c, struct response *r)
{
    struct motion_angle angle;
    motion_read_angle(c->d->motion, &angle);
    le_put_u16(&r->content[1], (uint16_t)angle.single_turn_decideg);
    r->length = 3;
    return OUTCOME_OK;
}

/* ReadMotion (0x40): one instant of the motion state, docs/packets.md. */
enum { READ_MOTION_ANSWER_LENGTH = 29 };
_Static_assert(offsetof(struct response, content) == sizeof(uint32_t) &&
                   __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
               "the answer's content is whole words, little-endian");

enum packet_outcome handle_read_motion(const struct packet_call *c, struct response *r)
{
    struct motion_diagnostics d;
    motion_read_diagnostics(c->d->motion, &d);
    /* Taken once: the content's stores could alias them, and every reload
     * is two loads on the answer's path. */
    const struct registers *regs = c->d->regs;
    uint32_t time_us = c->d->tick_us; /* the snapshot is the last tick's */
    uint32_t angle = (uint32_t)d.angle_decideg;
    uint32_t setpoint = (uint32_t)d.setpoint_decideg;
    uint32_t target = (uint32_t)d.target_decideg;
    uint32_t error = (uint16_t)d.tracking_error_centideg;
    uint32_t duty = (uint16_t)d.duty_q15;
    /* The fields (docs/packets.md) a word at a time: the content's bytes
     * 0-31, the ID first; the Cortex-M0 has 30 us for the whole answer and
     * no unaligned stores, where a field at a time is a byte a store. */
    uint32_t *w = &r->words[1];
    w[0] = r->content[0] | angle << 8;                              /* ID, angle */
    w[1] = angle >> 24 | setpoint << 8;                             /* setpoint */
    w[2] = setpoint >> 24 | target << 8;                            /* target */
    w[3] = target >> 24 | (uint32_t)(uint16_t)d.velocity_decideg_s << 8 | error << 24;
    w[4] = error >> 8 | (uint32_t)regs->status.current_ma << 8 |   /* error, current */
           (uint32_t)regs->status.status << 24;                    /* status */
    w[5] = d.flags | time_us << 8;                                  /* flags, time */
    w[6] = time_us >> 24 | (uint32_t)(uint16_t)regs->firmware.winding_decic << 8 | duty << 24;
    w[7] = duty >> 8;                                               /* duty */
    r->length = READ_MOTION_ANSWER_LENGTH;
    return OUTCOME_OK;
}

enum packet_outcome handle_read_multi_turn(const struct packet_call *c, struct response *r)
{
    struct motion_angle angle;
    motion_read_angle(c->d->motion, &angle);
    le_put_u32(&r->content[1], (uint32_t)angle.multi_turn_decideg);
    le_put_u16(&r->content[5], (uint16_t)angle.turns);
    r->length = 7;
    return OUTCOME_OK;
}

enum packet_outcome handle_reset_multi_turn(const struct packet_call *c, struct response *r)
{
    return answer_result(r, motion_reset_multi_turn(c->d->motion));
}

enum packet_outcome handle_set_origin(const struct packet_call *c, struct response *r)
{
    (void)r;
    return motion_set_origin(c->d->motion) ? OUTCOME_OK : OUTCOME_FAILED;
}

enum packet_outcome handle_begin_async(const struct packet_call *c, struct response *r)
{
    (void)r;
    motion_begin_async(c->d->motion);
    return OUTCOME_OK;
}

enum packet_outcome handle_end_async(const struct packet_call *c, struct response *r)
{
    (void)r;
    uint8_t cancel = c->content[0];
    if (cancel > FIELD_END_ASYNC_CANCEL_MAX) {
        return OUTCOME_ERROR;
    }
    motion_end_async(c->d->motion, cancel == 1u);
    return OUTCOME_OK;
}
