/* The frame finder: frames in a stream of bytes, noise and cut frames
 * costing only their own bytes. */
#include <string.h>

#include "servobus/servobus.h"

/* ---- the frame finder ---------------------------------------------------- */
void sb_parser_init(sb_parser *p, bool requests)
{
    memset(p, 0, sizeof *p);
    p->header[0] = requests ? SB_REQUEST_HEADER_0 : SB_RESPONSE_HEADER_0;
    p->header[1] = requests ? SB_REQUEST_HEADER_1 : SB_RESPONSE_HEADER_1;
}

/* The frame finder holds buf[0..len), seen of them examined, and starts at
 * a header (or holds nothing). Any header in the examined bytes begins a
 * candidate frame. A frame is returned the moment its last byte is
 * examined with a good checksum, whichever frames it overlaps: the one at
 * the start, else the earliest-starting that ends there. Nothing is dropped
 * for it but what can begin no frame any more: a frame inside another
 * (noise that looked like a header, an answer cut short, or a whole answer
 * whose content holds a frame of its own: a Monitor answer at 7173 mV holds
 * 05 1c 03 00 24) and a frame that begins inside one returned (noise that
 * made a good checksum with an answer's first bytes) are found too. A
 * candidate at the start that fails (a bad checksum, too long to be a
 * frame) costs only its first byte: the search goes on from the next. */

/* The size of the candidate at `at` once its head is examined, else 0. */
static size_t size_at(const sb_parser *p, size_t at)
{
    const uint8_t *b = p->buf + at;
    size_t have = p->seen - at;
    if (have < 4)
        return 0;
    if (b[3] != SB_EXTENDED_LENGTH)
        return 5u + b[3];
    return have < 6 ? 0 : 7u + ((size_t)b[4] | (size_t)b[5] << 8);
}

static bool header_at(const sb_parser *p, size_t at)
{
    return p->buf[at] == p->header[0] && (p->seen - at < 2 || p->buf[at + 1] == p->header[1]);
}

static bool checksum_ok(const sb_parser *p, size_t at, size_t size)
{
    return sb_checksum(p->buf + at, size - 1u) == p->buf[at + size - 1u];
}

/* Drops the first n bytes held (n <= seen). */
static void drop(sb_parser *p, size_t n)
{
    memmove(p->buf, p->buf + n, p->len - n);
    p->len -= n;
    p->seen -= n;
    p->owned = p->owned > n ? p->owned - n : 0;
    p->tie_from = p->tie_from > n ? p->tie_from - n : 0;
}

/* Drops examined bytes until the start is a header whose frame may still
 * end there (not too long, its end not passed: a candidate inside that
 * failed). stray: count them (not the rest of a frame that failed, nor a
 * frame's returned). */
static void settle(sb_parser *p, bool stray)
{
    while (p->seen > 0) {
        bool header = header_at(p, 0);
        size_t size = header ? size_at(p, 0) : 0;
        if (header && (size == 0 || (size <= SB_RX_MAX && size >= p->seen)))
            return;
        p->stray_bytes += stray && p->owned == 0 ? 1u : 0u;
        drop(p, 1);
    }
}

/* A frame that ends at the byte examined last and starts at from or after it. */
static bool ends_inside(const sb_parser *p, size_t from, size_t *start)
{
    for (size_t at = from; at + 5u <= p->seen; at++)
        if (header_at(p, at) && size_at(p, at) == p->seen - at && checksum_ok(p, at, p->seen - at)) {
            *start = at;
            return true;
        }
    return false;
}

/* After the byte at seen - 1 is examined: true when a frame ends there,
 * starting at *start (0, or inside the candidate at 0). */
static bool frame_ends(sb_parser *p, size_t *start)
{
    bool stray = true;
    *start = 0;
    for (;;) {
        settle(p, stray);
        if (p->seen == 0)
            return false;
        if (size_at(p, 0) != p->seen)
            break;
        if (checksum_ok(p, 0, p->seen))
            return true;
        p->bad_frames += p->owned == 0 ? 1u : 0u; /* not a header inside a frame returned */
        drop(p, 1);
        stray = false;
    }
    /* A frame that ends here, begun inside the unfinished one at the start
     * (inside a frame returned before, too: which of two frames that
     * overlap is the answer, the caller tells): returned, the one at the
     * start kept. */
    return ends_inside(p, 1, start);
}

/* Another frame that ends at the byte the one returned last ended at (two
 * overlapping frames, noise and an answer, may end at one byte). */
static bool another(sb_parser *p, size_t *start)
{
    *start = 0;
    if (p->tie_from == 0 && p->seen >= 5 && header_at(p, 0) && size_at(p, 0) == p->seen &&
        checksum_ok(p, 0, p->seen))
        return true;
    return ends_inside(p, p->tie_from > 1 ? p->tie_from : 1, start);
}

size_t sb_parser_missing(const sb_parser *p)
{
    size_t size = p->taken == 0 ? size_at(p, 0) : 0, held = p->len - p->taken;
    if (size == 0)
        return held < 5 ? 5u - held : 1u;
    return size > held ? size - held : 1u;
}

void sb_parser_clear(sb_parser *p)
{
    p->len = p->seen = p->taken = p->owned = p->tie_from = 0;
    p->tie = false;
}

/* The frame at `at`, ending at the byte examined last, handed back. */
static int hand(sb_parser *p, size_t at, uint8_t *code, const uint8_t **content, size_t *clen)
{
    size_t head = p->buf[at + 3] == SB_EXTENDED_LENGTH ? 6u : 4u;
    p->taken = at == 0 ? 1u : 0u;
    p->owned = at == 0 ? p->seen : p->owned;
    p->tie = true;
    p->tie_from = at + 1u;
    *code = p->buf[at + 2];
    *content = p->buf + at + head;
    *clen = p->seen - at - head - 1u;
    return 1;
}

int sb_parse(sb_parser *p, const uint8_t *data, size_t len, size_t *used, uint8_t *code, const uint8_t **content,
             size_t *clen)
{
    size_t k = 0, at = 0;
    drop(p, p->taken); /* the first byte of the frame returned last at the start */
    p->taken = 0;
    settle(p, true); /* and of its bytes, what can begin no frame any more */
    *used = 0;
    if (p->tie && another(p, &at))
        return hand(p, at, code, content, clen);
    p->tie = false;
    for (;;) {
        if (p->seen == p->len) { /* the held bytes examined: take the next (a live start leaves room) */
            if (k == len)
                break;
            p->buf[p->len++] = data[k++];
        }
        p->seen++;
        if (frame_ends(p, &at)) {
            *used = k;
            return hand(p, at, code, content, clen);
        }
    }
    *used = k;
    return 0;
}
