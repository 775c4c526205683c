#include <string.h>

#include "tests/fake_servo.h"

static void answer(fake_bus *f, uint8_t code, const sb_value *v, size_t count)
{
    size_t len = 0;
    sb_error e = sb_encode_answer(code, v, count, f->out + f->out_len, sizeof f->out - f->out_len, &len);
    if (e.status != SB_OK)
        return;
    if (f->garble_next) {
        f->out[f->out_len + len - 1] ^= 0x55u;
        f->garble_next = false;
    }
    f->out_len += len;
}

static void monitor(fake_bus *f, uint8_t id)
{
    sb_value v[8];
    memset(v, 0, sizeof v);
    v[0].n = id;
    v[1].n = 7400;
    v[5].n = 1;
    v[6].n = f->setpoint[id];
    if (f->present[id])
        answer(f, SB_PKT_MONITOR, v, 8);
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
    f->now_us += len * 10000000u / f->baud;
    while (at < len) {
        size_t used = 0, clen = 0;
        uint8_t code = 0;
        const uint8_t *content = NULL;
        if (sb_parse(&p, data + at, len - at, &used, &code, &content, &clen))
            take(f, code, content, clen);
        at += used;
    }
    return 0;
}

static int fake_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    fake_bus *f = (fake_bus *)ctx;
    size_t n = f->out_len - f->out_at;
    (void)want;
    if (n == 0) {
        f->now_us += wait_us;
        f->out_len = f->out_at = 0;
        return 0;
    }
    if (n > cap)
        n = cap;
    memcpy(buf, f->out + f->out_at, n);
    f->out_at += n;
    f->now_us += n * 10000000u / f->baud;
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
