/* Streamed setpoints (StreamSetpoint): each one starts a segment from
 * where the setpoint is (position and speed) to the host's, a cubic
 * (Hermite) one period long, walked at the tick rate; the segment's end
 * speed goes on until the next setpoint comes, and a period after that the
 * servo brakes to a hold (docs/streaming.md). Plans: divides. */
#include "motion/motion_internal.h"
#include "motion/saturate.h"

/* The period: item 69 if set, else the step between the host's stamps
 * (learned while a stream runs; 20 ms, 50 Hz, until then: motion_init). */
static uint32_t stream_period(struct motion *m, uint16_t host_ms)
{
    uint32_t since = (uint16_t)(host_ms - m->stream_host_ms);
    m->stream_host_ms = host_ms;
    if (m->streaming && since - 1u < PROFILE_MAX_SEGMENT) {
        m->stream_period_ms = (uint16_t)since;
    }
    uint32_t period = m->regs->firmware.stream_period_ms;
    return period != 0u ? period : m->stream_period_ms;
}

enum motion_submit_result motion_stream(struct motion *m, const struct motion_setpoint *sp)
{
    if (m->inhibit) {
        return MOTION_REFUSED; /* not counted (motion_submit) */
    }
    m->commands++;
    uint32_t period = stream_period(m, sp->host_ms);
    /* The stream's reference goes on from the setpoint, however the horn
     * lags (the profile's clock keeps the two together, and slows the
     * segment where it asks more than the output can give), or from the
     * horn at rest. */
    int32_t start = m->measured_q8;
    int32_t v0 = 0;
    if (m->mode == MODE_POSITION) {
        start = m->setpoint_q8;
        v0 = sat_q(start - m->last_setpoint_q8, PROFILE_MAX_SEGMENT_SPEED);
    }
    int32_t angle = clamp_i32(sp->angle_decideg, -MULTI_TURN_LIMIT, MULTI_TURN_LIMIT);
    int32_t distance = sat_q(angle * 256 + motion_center_offset_q8(m) - start,
                             PROFILE_MAX_SEGMENT_DISTANCE);
    /* 0.1 deg/s to Q8 decideg per tick: x 256 / 1000, as 16777 / 2^16
     * (an arithmetic shift: toward minus infinity, under 2^-8 decideg). */
    int32_t v1 = (clamp_i32(sp->velocity_decideg_s, -MAX_VELOCITY, MAX_VELOCITY) * 16777) >> 16;

    m->queue.count = 0;
    m->angle_clamped = 0;
    m->answer_packet = 0;
    m->power_mw = 0;
    motion_update_limits(m);
    profile_plan_segment(&m->profile, start, v0, start + distance, v1, period);
    motion_begin_profile(m, END_HOLD);
    m->endless = v1 != 0;
    m->streaming = 1;
    m->endless_until = 2u * period;
    return MOTION_ACCEPTED;
}
