#include "support/profile_closed_form.h"

/* k t^2 with k in Q40 and t <= PROFILE_MAX_RAMP: the result in Q32. With
 * |V|, |v0| <= PROFILE_MAX_VELOCITY (2^46), |k t| <= 2^54 for t within the
 * ramp, so |(k t) >> 8| t <= 2^62. */
static int64_t square_term(int64_t k, uint32_t t)
{
    return ((k * (int64_t)t) >> 8) * (int64_t)t;
}

/* The first phase: v0 t + k t^2, and a segment's j t^3. */
static int64_t ramp_position(const struct profile *p, uint32_t tick)
{
    int64_t at = p->start + p->v0 * (int64_t)tick + square_term(p->accel_k, tick);
    return p->accel_j != 0 ? at + ((p->accel_j * (int64_t)(tick * tick * tick)) >> 8) : at;
}

int64_t profile_position(const struct profile *p, uint32_t tick)
{
    if (tick < p->accel_ticks) {
        return ramp_position(p, tick);
    }
    if (tick < p->cruise_end) {
        return ramp_position(p, p->accel_ticks) + p->cruise * (int64_t)(tick - p->accel_ticks);
    }
    if (tick >= p->total_ticks) {
        return p->target;
    }
    return p->target - square_term(p->decel_k, p->total_ticks - tick);
}
