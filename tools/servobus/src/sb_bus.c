/* The bus: answers matched to requests on the bus's clock (their frames
 * found by sb_parse.c); a microcontroller's UART as a transport. */
#include <errno.h>
#include <limits.h>
#include <string.h>

#include "servobus/servobus.h"

#define WAIT_SLICE_US 5000u /* the longest single wait on the transport */
#define EINTR_TRIES 16      /* a call a signal interrupted is made again, but not forever */

/* ---- the bus ------------------------------------------------------------- */
void sb_bus_init(sb_bus *bus, sb_transport t, uint32_t baud)
{
    memset(bus, 0, sizeof *bus);
    bus->t = t;
    bus->baud = baud;
    bus->timeout_us = 100000u;
    bus->answer_margin_us = SB_ANSWER_MARGIN_US;
    sb_parser_init(&bus->rx, false);
}

/* bytes' time on the wire at the bus's baud rate */
static uint64_t wire_us(const sb_bus *bus, size_t bytes)
{
    return bus->baud > 0 ? ((uint64_t)bytes * SB_BITS_PER_BYTE * 1000000u + bus->baud - 1u) / bus->baud : 0u;
}

/* A time us after t on the bus clock, held at its end rather than wrapping. */
static uint64_t later(uint64_t t, uint64_t us)
{
    return t > UINT64_MAX - us ? UINT64_MAX : t + us;
}

static sb_error link_error(int rc, uint8_t code)
{
    sb_error e = sb_ok();
    e.status = SB_E_LINK;
    e.packet = code;
    e.os_error = rc >= -INT_MAX ? -rc : EIO; /* INT_MIN has no errno (nor a negation) */
    return e;
}

/* The transport's read into pending, its return checked: more than it
 * holds is a broken link (it wrote past the buffer). */
static int link_read(sb_bus *bus, size_t want, uint32_t wait_us)
{
    int rc = -EINTR;
    for (int tries = 0; rc == -EINTR && tries < EINTR_TRIES; tries++)
        rc = bus->t.read(bus->t.ctx, bus->pending, sizeof bus->pending, want, wait_us);
    return rc > (int)sizeof bus->pending ? -EOVERFLOW : rc;
}

/* The transport's write: 0 (or len, a count of all of it), else -errno. */
static int link_write(sb_bus *bus, const uint8_t *frame, size_t len)
{
    int rc = -EINTR;
    for (int tries = 0; rc == -EINTR && tries < EINTR_TRIES; tries++)
        rc = bus->t.write(bus->t.ctx, frame, len);
    return rc > 0 && (size_t)rc != len ? -EIO : rc > 0 ? 0 : rc;
}

sb_error sb_send(sb_bus *bus, const uint8_t *frame, size_t len)
{
    int rc;
    /* What waits unread is dropped: a late answer is not the next one's.
     * As much as the buffer holds each read (a UART's callbacks would give
     * a byte a call), 64 buffers at most: a line that never stops talking
     * is not waited out. */
    for (int k = 0; k < 64; k++) {
        rc = link_read(bus, sizeof bus->pending, 0);
        if (rc < 0)
            return link_error(rc, len > 2 ? frame[2] : 0);
        if (rc == 0)
            break;
    }
    bus->pending_len = 0;
    sb_parser_clear(&bus->rx);
    bus->sent_end_us = later(bus->t.now_us(bus->t.ctx), wire_us(bus, len));
    rc = link_write(bus, frame, len);
    return rc < 0 ? link_error(rc, len > 2 ? frame[2] : 0) : sb_ok();
}

/* Whether a frame of a call's answer decodes: a packet with a fixed
 * answer size, by its length; another, decoded. */
static sb_error fits(uint8_t code, const uint8_t *content, size_t len)
{
    size_t size = sb_answer_frame_size(code);
    const sb_packet_desc *p = sb_packet(code);
    sb_value v[SB_ANSWER_CONTENT_MAX];
    sb_error e = sb_ok();
    if (size > 0 && len + 5u != size) { /* "length: 2 bytes, not 16" */
        e = sb_error_of(SB_E_BAD_ANSWER, len > 0 ? content[0] : -1, code, "length");
        e.value = (int64_t)len;
        e.least = e.most = (int64_t)size - 5;
    } else if (size == 0 && p != NULL && p->answer_count <= SB_ANSWER_CONTENT_MAX) {
        e = sb_decode_answer(code, content, len, v, p->answer_count);
    }
    return e;
}

/* sb_receive of an answer about item (its second byte; -1: any); the
 * transport may wait for want_after bytes (0: this frame's); look: once the
 * deadline has passed, one last look at what came meanwhile (else only the
 * bytes held are searched). A frame of the servo's that does not fit the
 * packet (one inside its answer) is skipped, the answer may yet end; if
 * only such frames came, the first one's error. */
static sb_error receive(sb_bus *bus, uint8_t code, int servo, int item, uint64_t deadline_us, uint8_t *content,
                        size_t *len, size_t want_after, bool look)
{
    uint32_t bad = bus->rx.bad_frames;
    sb_error e = sb_ok(), misfit = sb_ok(); /* the first answer of the servo that did not decode: skipped */
    bool looked = !look; /* the deadline passed: one last look at what came meanwhile */
    int other = -1;      /* the item of an answer about another, skipped */
    for (;;) {
        for (;;) { /* every frame in what came and what the finder holds */
            size_t used = 0, clen = 0;
            uint8_t fcode = 0;
            const uint8_t *fcontent = NULL;
            int got = sb_parse(&bus->rx, bus->pending, bus->pending_len, &used, &fcode, &fcontent, &clen);
            memmove(bus->pending, bus->pending + used, bus->pending_len - used);
            bus->pending_len -= used;
            if (!got)
                break;
            if (fcode == code && (servo < 0 || (clen > 0 && fcontent[0] == servo)) && item >= 0 &&
                (clen < 2 || fcontent[1] != item)) {
                other = clen < 2 ? 256 : fcontent[1]; /* a late answer about another item: skipped */
            } else if (fcode == code && (servo < 0 || (clen > 0 && fcontent[0] == servo))) {
                sb_error d = servo >= 0 && clen <= SB_ANSWER_CONTENT_MAX ? fits(code, fcontent, clen) : sb_ok();
                if (d.status != SB_OK) { /* a frame inside the answer, say: the answer may yet end */
                    misfit = misfit.status != SB_OK ? misfit : d;
                    continue;
                }
                bus->arrived_us = bus->t.now_us(bus->t.ctx);
                if (clen > SB_ANSWER_CONTENT_MAX) {
                    e = sb_error_of(SB_E_BAD_ANSWER, fcontent[0], code, "length");
                    e.value = (int64_t)clen;
                    e.most = SB_ANSWER_CONTENT_MAX;
                    return e;
                }
                memcpy(content, fcontent, clen);
                *len = clen;
                return e;
            }
        }
        {
            uint64_t now = bus->t.now_us(bus->t.ctx);
            uint64_t left = deadline_us > now ? deadline_us - now : 0;
            int rc;
            if (left == 0 && !looked) { /* the host may have slept past the deadline: bytes wait */
                looked = true;
                rc = link_read(bus, 1, 0);
                if (rc > 0) {
                    bus->pending_len = (size_t)rc;
                    continue;
                }
            }
            if (left == 0) {
                e.status = bus->rx.bad_frames != bad ? SB_E_BAD_CHECKSUM : SB_E_NO_ANSWER;
                e.servo = (int16_t)servo;
                e.packet = code;
                if (other >= 0) { /* only answers about another item came */
                    e = sb_error_of(SB_E_BAD_ANSWER, servo, code, "data_id");
                    e.value = other;
                    e.least = e.most = item;
                }
                e = misfit.status != SB_OK ? misfit : e; /* only answers that did not decode came */
                return e;
            }
            /* want_after: the bytes of every frame still to come, from this one's first. */
            size_t want = want_after > bus->rx.len ? want_after - bus->rx.len : sb_parser_missing(&bus->rx);
            rc = link_read(bus, want, (uint32_t)(left < WAIT_SLICE_US ? left : WAIT_SLICE_US));
            if (rc < 0) {
                e = link_error(rc, code);
                e.servo = (int16_t)servo;
                return e;
            }
            bus->pending_len = (size_t)rc;
        }
    }
}

sb_error sb_receive(sb_bus *bus, uint8_t code, int servo, uint64_t deadline_us, uint8_t *content, size_t *len)
{
    return receive(bus, code, servo, -1, deadline_us, content, len, 0, true);
}

sb_error sb_request(sb_bus *bus, size_t len, uint8_t code, int servo, uint8_t *content, size_t *clen)
{
    return sb_request_item(bus, len, code, servo, -1, content, clen);
}

sb_error sb_request_item(sb_bus *bus, size_t len, uint8_t code, int servo, int item, uint8_t *content, size_t *clen)
{
    sb_error e = servo == SB_BROADCAST_ID ? sb_error_of(SB_E_BROADCAST, servo, code, "id") : sb_ok();
    if (e.status == SB_OK)
        e = sb_send(bus, bus->tx, len);
    if (e.status != SB_OK) {
        e.servo = (int16_t)servo;
        return e;
    }
    e = receive(bus, code, servo, item, later(bus->t.now_us(bus->t.ctx), bus->timeout_us), content, clen, 0, true);
    if (e.status == SB_E_NO_ANSWER && code == SB_PKT_ASSIGN_ID && len >= 10u) {
        /* Only the servo with the serial answers, whatever its ID: none did. */
        e.field = "serial";
        e.value = (int64_t)((uint32_t)bus->tx[5] | (uint32_t)bus->tx[6] << 8 | (uint32_t)bus->tx[7] << 16 |
                            (uint32_t)bus->tx[8] << 24);
    }
    return e;
}

/* The slot in the list an answer of id takes, or count (not asked for). */
static size_t slot_of(const uint8_t *ids, size_t count, uint8_t id)
{
    size_t k = 0;
    while (k < count && ids[k] != id)
        k++;
    return k;
}

sb_error sb_sync_monitor_answers(sb_bus *bus, const uint8_t *ids, size_t count, sb_monitor_answer *states, bool *got)
{
    size_t answer = sb_answer_frame_size(SB_PKT_MONITOR), left = count, next = 0, silent = 0;
    /* An answer's wait from the line's last activity: the servo's
     * turnaround, its bytes, the link's margin; each listed servo before it
     * that stays silent adds the silence that passes its turn. */
    uint64_t slot = SB_TURNAROUND_US + wire_us(bus, 2u + answer) + bus->answer_margin_us;
    uint64_t last = bus->sent_end_us, held_us = 0;
    /* The round's end, however the line babbles: each listed servo's slot and silence. */
    uint64_t end = later(last, (uint64_t)count * (slot + SB_SYNC_SILENCE_US));
    bool over = false; /* the end has passed: only the bytes held are searched */
    uint32_t bad = bus->rx.bad_frames;
    size_t misshapen = count; /* the first listed servo whose answer was bad (its length, a field's range) */
    sb_error misshapen_e = sb_ok(); /* what was wrong with it */
    size_t held = count; /* a servo not passed whose frame of the wrong length came this turn */
    size_t floor = 0;    /* every servo before it has passed its turn: a servo after it answered in turn */
    bool jumped = false; /* the last answer taken came before a listed servo's that had not passed its turn */
    uint32_t taken_end = 0; /* the byte after the last answer taken (the parser's count, from the request) */
    sb_error e = sb_ok();
    for (size_t k = 0; k < count; k++)
        got[k] = false;
    /* Only a servo whose turn has not passed is taken: not one that
     * answered, nor one before a servo that answered in its turn (a frame
     * inside two answers can name either); one merely slower than its slot
     * still is. An
     * answer ahead of ids[next] (a late one of the round before, or a
     * servo's after silences shorter than the margin) gives one more slot,
     * and the servos it passed may still answer, dropping it. */
    while (left > 0 && (next < count || jumped)) {
        uint8_t content[SB_ANSWER_CONTENT_MAX];
        size_t len = 0, k;
        sb_monitor_answer a;
        uint64_t deadline = later(last, silent * SB_SYNC_SILENCE_US + slot);
        deadline = deadline < end ? deadline : end;
        e = receive(bus, SB_PKT_MONITOR, -1, -1, deadline, content, &len, left * answer, !over);
        over = over || bus->t.now_us(bus->t.ctx) >= end;
        if ((e.status == SB_E_NO_ANSWER || e.status == SB_E_BAD_CHECKSUM) && (next >= count || deadline == end))
            break;
        if ((e.status == SB_E_NO_ANSWER || e.status == SB_E_BAD_CHECKSUM) && held < count) {
            /* no answer ended after the frame of the wrong length: it took the turn */
            last = held_us;
            silent = 0;
            next = held + 1;
            held = count;
            jumped = false;
            continue;
        }
        if (e.status == SB_E_NO_ANSWER || e.status == SB_E_BAD_CHECKSUM) {
            silent++; /* ids[next] passes its turn; the next answers after the silence */
            next++;
            jumped = false;
            continue;
        }
        if (e.status == SB_OK)
            e = sb_decode_monitor(content, len, &a);
        if (e.status == SB_E_BAD_ANSWER) { /* its checksum good, its length or a field's range not: skipped */
            sb_error bad_e = e;
            k = e.servo >= 0 ? slot_of(ids, count, (uint8_t)e.servo) : count;
            e = sb_ok();
            if (k == count || k < floor || got[k])
                continue; /* not asked for, or its turn passed */
            if (k < misshapen) {
                misshapen = k;
                misshapen_e = bad_e;
            }
            if (k >= next && k < held) { /* the real answer may yet end within the slot */
                held = k;
                held_us = bus->arrived_us;
            }
            continue;
        }
        if (e.status != SB_OK)
            break;
        k = slot_of(ids, count, a.id);
        if (k == count || k < floor || got[k])
            continue; /* not asked for, or its turn passed */
        /* A frame begun inside an answer taken is made of that answer's
         * bytes and the next one's (its checksum good by chance): the
         * answers on the line follow each other. */
        if ((int32_t)(bus->rx.start - taken_end) < 0)
            continue;
        /* A round answers in the list's order: what was taken of a later
         * servo came before this, so it was an earlier round's, late. */
        for (size_t j = k + 1; j < count; j++)
            if (got[j]) {
                got[j] = false;
                left++;
            }
        states[k] = a;
        got[k] = true;
        taken_end = bus->rx.end;
        left--;
        last = bus->arrived_us;
        silent = 0;
        jumped = k > next;
        floor = jumped ? floor : k + 1;
        next = k + 1;
        held = count;
    }
    if (e.status == SB_OK || e.status == SB_E_NO_ANSWER || e.status == SB_E_BAD_CHECKSUM) {
        e = sb_ok();
        for (size_t k = 0; k < count; k++)
            if (!got[k]) { /* the first that did not answer */
                e.status = bus->rx.bad_frames != bad ? SB_E_BAD_CHECKSUM : SB_E_NO_ANSWER;
                e.servo = ids[k];
                e.packet = SB_PKT_MONITOR;
                if (k == misshapen) /* what the decoder said: "length: 2 bytes, not 16", a field's range */
                    e = misshapen_e;
                break;
            }
    }
    return e;
}

sb_error sb_sync_monitor(sb_bus *bus, const uint8_t *ids, size_t count, sb_monitor_answer *states, bool *got)
{
    size_t len = 0;
    sb_error e;
    for (size_t k = 0; k < count; k++)
        got[k] = false; /* none, if the round is refused or the link fails */
    e = sb_check_ids(ids, count, SB_PKT_MONITOR);
    if (e.status == SB_OK && count == 0) { /* the Sync Monitor's, not the SyncCommand it rides in */
        e = sb_error_of(SB_E_USAGE, -1, SB_PKT_MONITOR, "ids");
        e.least = 1;
        e.most = 255;
    }
    if (e.status == SB_OK)
        e = sb_sync_frame(SB_PKT_MONITOR, ids, 1, count, bus->tx, sizeof bus->tx, &len);
    if (e.status == SB_OK)
        e = sb_send(bus, bus->tx, len);
    return e.status == SB_OK ? sb_sync_monitor_answers(bus, ids, count, states, got) : e;
}

/* ---- a microcontroller's UART -------------------------------------------- */
static int uart_write(void *ctx, const uint8_t *data, size_t len)
{
    sb_uart *u = (sb_uart *)ctx;
    u->send(u->ctx, data, len);
    return 0;
}

static int uart_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    sb_uart *u = (sb_uart *)ctx;
    uint64_t start = u->now_us(u->ctx);
    size_t n = 0;
    while (n < cap) {
        int c = u->recv(u->ctx);
        if (c >= 0) {
            buf[n++] = (uint8_t)c;
            if (n >= want)
                break;
        } else if (n > 0 || u->now_us(u->ctx) - start >= wait_us) {
            break;
        }
    }
    return (int)n;
}

static uint64_t uart_now(void *ctx)
{
    sb_uart *u = (sb_uart *)ctx;
    return u->now_us(u->ctx);
}

sb_transport sb_uart_transport(sb_uart *uart)
{
    return sb_transport_make(uart, uart_write, uart_read, uart_now);
}
