#include <errno.h>
#include <string.h>

#include "tests/fake_servo.h"

/* len bytes just put in out, their last off the wire us after the line's last activity */
static void queue(fake_bus *f, size_t len, uint64_t us)
{
    if (f->answers == sizeof f->ends / sizeof f->ends[0])
        return;
    f->out_len += len;
    f->line_us += us;
    f->ends[f->answers] = f->out_len;
    f->ready_us[f->answers++] = f->line_us;
}

static void answer(fake_bus *f, uint8_t code, const sb_value *v, size_t count)
{
    size_t len = 0;
    uint8_t id = (uint8_t)v[0].n, *frame = f->out + f->out_len;
    sb_error e = sb_encode_answer(code, v, count, frame, sizeof f->out - f->out_len, &len);
    if (e.status != SB_OK)
        return;
    if (f->one_short[id]) /* its content less its last byte, framed anew */
        sb_frame(false, code, frame + 4, (size_t)frame[3] - 1u, frame, sizeof f->out - f->out_len, &len);
    if (f->cut[id] > 0 && f->cut[id] < len)
        len = f->cut[id];
    if (f->garble_next) {
        f->out[f->out_len + len - 1] ^= 0x55u;
        f->garble_next = false;
    }
    queue(f, len, (f->first ? FAKE_FIRST_US : FAKE_NEXT_US) + len * 10000000u / f->baud);
    f->first = false;
}

static void monitor(fake_bus *f, uint8_t id)
{
    sb_value v[8];
    memset(v, 0, sizeof v);
    v[0].n = id;
    v[1].n = f->power[0] != 0 ? f->power[0] : 7400;
    v[2].n = f->power[1];
    v[3].n = f->power[2];
    v[5].n = 1;
    v[6].n = f->setpoint[id];
    if (f->present[id])
        answer(f, SB_PKT_MONITOR, v, 8);
    else
        f->line_us += SB_SYNC_SILENCE_US; /* the next listed servo waits out its silence */
}

static void take(fake_bus *f, uint8_t code, const uint8_t *c, size_t len)
{
    sb_value v[4];
    f->frames++;
    if (code == SB_PKT_PING && len == 1 && f->present[c[0]]) {
        memset(v, 0, sizeof v);
        v[0].n = c[0];
        answer(f, SB_PKT_PING, v, 1);
    } else if (code == SB_PKT_READ_ANGLE && len == 1 && f->present[c[0]]) {
        memset(v, 0, sizeof v);
        v[0].n = c[0];
        v[1].n = -123;
        answer(f, SB_PKT_READ_ANGLE, v, 2);
    } else if (code == SB_PKT_MONITOR && len == 1) {
        monitor(f, c[0]);
    } else if (code == SB_PKT_STREAM_SETPOINT && len == 9) {
        f->setpoint_frames++;
        if (sb_decode_request(code, c, len, v, 4).status == SB_OK) {
            f->setpoint[c[0]] = (int32_t)v[1].n;
            f->velocity[c[0]] = (int16_t)v[2].n;
            f->stamp[c[0]] = (uint16_t)v[3].n;
        }
    } else if (code == SB_PKT_SYNC_COMMAND && len >= 3 && len == 3u + (size_t)c[1] * c[2]) {
        for (size_t k = 0; k < c[2]; k++)
            take(f, c[0], c + 3 + k * c[1], c[1]);
        f->frames -= c[2];
        if (c[0] == SB_PKT_STREAM_SETPOINT)
            f->setpoint_frames -= (uint32_t)c[2] - 1u;
    }
}

static int fake_write(void *ctx, const uint8_t *data, size_t len)
{
    fake_bus *f = (fake_bus *)ctx;
    sb_parser p;
    size_t at = 0;
    sb_parser_init(&p, true);
    if (f->fail_writes > 0) {
        f->fail_writes--;
        return -EIO;
    }
    if (f->late_len > 0) { /* a late answer, its last byte off the wire as the request starts */
        memcpy(f->out + f->out_len, f->late, f->late_len);
        f->line_us = f->now_us;
        queue(f, f->late_len, 0);
        f->late_len = 0;
    }
    f->now_us += len * 10000000u / f->baud;
    f->line_us = f->now_us;
    f->first = true;
    for (;;) {
        size_t used = 0, clen = 0;
        uint8_t code = 0;
        const uint8_t *content = NULL;
        int got = sb_parse(&p, data + at, len - at, &used, &code, &content, &clen);
        at += used;
        if (!got)
            break;
        take(f, code, content, clen);
    }
    return 0;
}

/* What is off the wire by now: whole answers (a wait moves the clock to
 * the next one's end, or by wait_us). */
static int fake_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    fake_bus *f = (fake_bus *)ctx;
    size_t k = 0, n;
    (void)want;
    while (k < f->answers && f->ends[k] <= f->out_at)
        k++;
    if (k == f->answers) {
        f->now_us += wait_us;
        f->out_len = f->out_at = f->answers = 0;
        return 0;
    }
    if (f->ready_us[k] > f->now_us) {
        if (f->ready_us[k] - f->now_us > wait_us) {
            f->now_us += wait_us;
            return 0;
        }
        f->now_us = f->ready_us[k];
    }
    while (k + 1 < f->answers && f->ready_us[k + 1] <= f->now_us)
        k++;
    n = f->ends[k] - f->out_at;
    if (n > cap)
        n = cap;
    memcpy(buf, f->out + f->out_at, n);
    f->out_at += n;
    return (int)n;
}

static uint64_t fake_now(void *ctx)
{
    return ((fake_bus *)ctx)->now_us;
}

void fake_init(fake_bus *f, uint32_t baud)
{
    memset(f, 0, sizeof *f);
    f->baud = baud;
}

sb_transport fake_transport(fake_bus *f)
{
    return sb_transport_make(f, fake_write, fake_read, fake_now);
}
