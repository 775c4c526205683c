/* SyncCommand, the stream of setpoints and the robot loop. */
#include <string.h>

#include "servobus/servobus.h"

#define SETPOINT_LEN 9u /* a StreamSetpoint's content */

static sb_error usage(int servo, uint8_t code, const char *field)
{
    return sb_error_of(SB_E_USAGE, servo, code, field);
}

/* A number the call does not allow: value, and the range it must be in. */
static sb_error usage_of(uint8_t code, const char *field, int64_t value, int64_t least, int64_t most)
{
    sb_error e = usage(-1, code, field);
    e.value = value;
    e.least = least;
    e.most = most;
    return e;
}

sb_error sb_sync_command(sb_bus *bus, uint8_t cmd, const uint8_t *records, size_t record_len, size_t count)
{
    size_t len = 0;
    sb_error e = sb_sync_frame(cmd, records, record_len, count, bus->tx, sizeof bus->tx, &len);
    return e.status == SB_OK ? sb_send(bus, bus->tx, len) : e;
}

/* ---- the stream ----------------------------------------------------------- */
sb_error sb_stream_init(sb_stream *s, const uint8_t *ids, size_t count, uint16_t period_ms)
{
    const sb_field_desc *angle = &sb_packet(SB_PKT_STREAM_SETPOINT)->request[1];
    const sb_item_desc *period = sb_item(SB_ITEM_STREAM_PERIOD_MS);
    sb_error e;
    memset(s, 0, sizeof *s);
    if (count == 0 || count > SB_MAX_SERVOS) /* none listed, or more than the structs hold */
        return usage_of(SB_PKT_STREAM_SETPOINT, "ids", (int64_t)count, 1, SB_MAX_SERVOS);
    if (period_ms < 1 || period_ms > period->max) /* item 69's range, but for its 0 (off) */
        return usage_of(SB_PKT_STREAM_SETPOINT, "period_ms", period_ms, 1, period->max);
    e = sb_check_ids(ids, count, SB_PKT_STREAM_SETPOINT);
    if (e.status != SB_OK)
        return e;
    for (size_t k = 0; k < count; k++) {
        s->ids[k] = ids[k];
        s->angle_min[k] = (int32_t)angle->min;
        s->angle_max[k] = (int32_t)angle->max;
    }
    s->count = count;
    s->period_ms = period_ms;
    return sb_ok();
}

static sb_error refused(int servo, const char *field, int64_t value, int64_t least, int64_t most)
{
    sb_error e = usage(servo, SB_PKT_STREAM_SETPOINT, field);
    e.status = SB_E_RANGE;
    e.value = value;
    e.least = least;
    e.most = most;
    return e;
}

sb_error sb_stream_frame(sb_stream *s, const int32_t *angles, const int16_t *velocities, uint8_t *frame, size_t cap,
                         size_t *len)
{
    return sb_stream_frame_at(s, angles, velocities, s->sent * (uint32_t)s->period_ms, frame, cap, len);
}

sb_error sb_stream_frame_at(sb_stream *s, const int32_t *angles, const int16_t *velocities, uint32_t at_ms,
                            uint8_t *frame, size_t cap, size_t *len)
{
    uint8_t records[SETPOINT_LEN * SB_MAX_SERVOS];
    int64_t top = sb_packet(SB_PKT_STREAM_SETPOINT)->request[2].max; /* the servo's top speed, 0.1 deg/s */
    sb_error e = sb_ok();
    for (size_t k = 0; k < s->count; k++) {
        sb_value v[4];
        size_t rlen = 0;
        int64_t step = s->sent > 0 ? (int64_t)angles[k] - s->last[k] : 0;
        memset(v, 0, sizeof v);
        v[0].n = s->ids[k];
        v[1].n = angles[k];
        v[2].n = velocities != NULL ? velocities[k] : (step * 1000 + (step < 0 ? -1 : 1) * s->period_ms / 2) / s->period_ms;
        v[3].n = (int64_t)(at_ms & 0xFFFFu);
        if (angles[k] < s->angle_min[k] || angles[k] > s->angle_max[k])
            return refused(s->ids[k], "angle", angles[k], s->angle_min[k], s->angle_max[k]);
        if ((step < 0 ? -step : step) * 1000 > top * s->period_ms)
            return refused(s->ids[k], "angle step", step, -top * s->period_ms / 1000, top * s->period_ms / 1000);
        e = sb_encode_content(SB_PKT_STREAM_SETPOINT, v, 4, records + k * SETPOINT_LEN, SETPOINT_LEN, &rlen);
        if (e.status != SB_OK)
            return e;
    }
    if (s->count == 1)
        e = sb_frame(true, SB_PKT_STREAM_SETPOINT, records, SETPOINT_LEN, frame, cap, len);
    else
        e = sb_sync_frame(SB_PKT_STREAM_SETPOINT, records, SETPOINT_LEN, s->count, frame, cap, len);
    if (e.status != SB_OK)
        return e;
    for (size_t k = 0; k < s->count; k++)
        s->last[k] = angles[k];
    /* Past UINT32_MAX, 65536 rather than 0: the step stays checked and the
     * grid's time stamps (sent * period mod 65536) run on without a jump. */
    if (++s->sent == 0)
        s->sent = 65536u;
    return e;
}

/* ---- the robot loop ------------------------------------------------------- */
sb_error sb_loop_init(sb_loop *l, sb_bus *bus, const uint8_t *ids, size_t count, uint16_t period_ms)
{
    uint64_t wire;
    sb_error e;
    memset(l, 0, sizeof *l);
    l->bus = bus;
    e = sb_stream_init(&l->stream, ids, count, period_ms);
    if (e.status != SB_OK)
        return e;
    if (bus->baud == 0) /* no wire's time to pace a loop by */
        return usage_of(SB_PKT_STREAM_SETPOINT, "baud", 0, 1, UINT32_MAX);
    /* A period shorter than the cycle's own bytes on the wire cannot be kept
     * (servoctl's check_wire): the least is that time, rounded up to a ms. */
    wire = ((uint64_t)sb_cycle_bytes(count) * SB_BITS_PER_BYTE * 1000u + bus->baud - 1u) / bus->baud;
    if ((uint64_t)period_ms < wire)
        return usage_of(SB_PKT_STREAM_SETPOINT, "period_ms", period_ms, (int64_t)wire,
                        sb_item(SB_ITEM_STREAM_PERIOD_MS)->max);
    e = sb_sync_frame(SB_PKT_MONITOR, ids, 1, count, l->monitor, sizeof l->monitor, &l->monitor_len);
    if (e.status != SB_OK)
        l->monitor_len = 0;
    return e;
}

sb_error sb_loop_cycle(sb_loop *l, const int32_t *angles, const int16_t *velocities, sb_monitor_answer *states,
                       bool *got)
{
    sb_bus *bus = l->bus;
    sb_stream before;
    uint64_t now_us;
    size_t len = 0;
    sb_error e;
    if (l->monitor_len == 0) /* sb_loop_init refused it: nothing is sent */
        return usage(-1, SB_PKT_STREAM_SETPOINT, "loop");
    for (size_t k = 0; k < l->stream.count; k++)
        got[k] = false; /* none, if the setpoints are refused or the link fails */
    before = l->stream;
    now_us = bus->t.now_us(bus->t.ctx);
    /* Stamped with the bus clock's now: the moment the caller's setpoints
     * are for, late or early, which the servo plays on its own timeline. */
    e = sb_stream_frame_at(&l->stream, angles, velocities, (uint32_t)(now_us / 1000u), bus->tx,
                           sizeof bus->tx - l->monitor_len, &len);
    if (e.status != SB_OK)
        return e;
    if (l->cycles == 0)
        l->started_us = now_us;
    /* One write: the Sync Monitor follows the setpoints without a gap. */
    memcpy(bus->tx + len, l->monitor, l->monitor_len);
    e = sb_send(bus, bus->tx, len + l->monitor_len);
    if (e.status != SB_OK) {
        /* The servos did not get these setpoints: the next step is checked
         * (and its speed made) from the last they got. */
        l->stream = before;
        return e;
    }
    e = sb_sync_monitor_answers(bus, l->stream.ids, l->stream.count, states, got);
    for (size_t k = 0; k < l->stream.count; k++)
        l->missed += got[k] ? 0u : 1u;
    l->cycles++;
    return e;
}

static size_t frame_bytes(size_t content)
{
    return (content >= SB_EXTENDED_LENGTH ? 7u : 5u) + content;
}

size_t sb_cycle_bytes(size_t count)
{
    size_t setpoints = count == 1 ? frame_bytes(SETPOINT_LEN) : frame_bytes(3u + SETPOINT_LEN * count);
    return setpoints + frame_bytes(3u + count) + count * sb_answer_frame_size(SB_PKT_MONITOR);
}

double sb_wire_limit_hz(size_t count, uint32_t baud)
{
    return (double)baud / SB_BITS_PER_BYTE / (double)sb_cycle_bytes(count);
}

double sb_loop_rate_hz(const sb_loop *l)
{
    uint64_t now = l->bus->t.now_us(l->bus->t.ctx);
    return now > l->started_us ? (double)l->cycles * 1e6 / (double)(now - l->started_us) : 0.0;
}
