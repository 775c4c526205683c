/* The frame finder: frames in a stream of bytes, noise and cut frames
 * costing only their own bytes. */
#include <string.h>

#include "servobus/servobus.h"

/* Every header begins a candidate frame; the candidates are kept by the
 * byte they end at once their length is read, in the order they begin. A
 * candidate is checked when its last byte comes, its checksum from two
 * running sums (the bytes before its start, before its end): returned if
 * good, whichever frames it overlaps (noise that looked like a header, an
 * answer cut short, a whole answer whose content holds a frame of its
 * own: a Monitor answer at 7173 mV holds 05 1c 03 00 24), else given up,
 * costing its first byte only. So a byte costs a few steps and one check
 * for each candidate that ends at it, never a pass over the bytes held:
 * frames come back in the order of their last byte, then of their first. */
#define N SB_RX_MAX          /* the bytes a candidate spans at most */
#define NONE 0xFFFFu         /* the end of a list */
#define PENDING 0x4000u      /* size: a header, its length not yet read */
#define DONE 0x8000u         /* size: checked (returned or given up) */
#define SPAN(v) ((v) & 0x3FFu) /* size: the candidate's bytes */

void sb_parser_init(sb_parser *p, bool requests)
{
    memset(p, 0, sizeof *p);
    memset(p->ends, 0xFF, sizeof p->ends);
    p->cursor = NONE;
    p->header[0] = requests ? SB_REQUEST_HEADER_0 : SB_RESPONSE_HEADER_0;
    p->header[1] = requests ? SB_REQUEST_HEADER_1 : SB_RESPONSE_HEADER_1;
}

void sb_parser_clear(sb_parser *p)
{
    uint32_t stray = p->stray_bytes, bad = p->bad_frames;
    uint8_t h0 = p->header[0], h1 = p->header[1];
    sb_parser_init(p, false);
    p->header[0] = h0;
    p->header[1] = h1;
    p->stray_bytes = stray;
    p->bad_frames = bad;
}

static uint8_t at(const sb_parser *p, uint32_t x)
{
    return p->buf[x % N];
}

/* A candidate not yet checked (or its length not yet read). */
static bool open_at(const sb_parser *p, uint32_t s)
{
    uint16_t v = p->size[s % N];
    return (v & PENDING) != 0 || (v != 0 && (v & DONE) == 0);
}

/* The candidate at s, its size now read: kept by the byte it ends at,
 * after those that begin before it (they are longer). */
static void keep(sb_parser *p, uint32_t s, size_t size)
{
    uint16_t *link;
    if (size > N) { /* too long to be a frame: no candidate */
        p->size[s % N] = 0;
        return;
    }
    p->size[s % N] = (uint16_t)size;
    link = &p->ends[(s + size - 1u) % N];
    while (*link != NONE && SPAN(p->size[*link]) > size)
        link = &p->next[*link];
    p->next[s % N] = *link;
    *link = (uint16_t)(s % N);
}

/* Byte x taken: a header ends at it, or a candidate's length. */
static void take(sb_parser *p, uint8_t b)
{
    uint32_t x = p->now++;
    p->buf[x % N] = p->buf[x % N + N] = b;
    p->size[x % N] = 0;
    if (x >= 1 && at(p, x - 1) == p->header[0] && b == p->header[1])
        p->size[(x - 1) % N] = PENDING;
    if (x >= 3 && p->size[(x - 3) % N] == PENDING && b != SB_EXTENDED_LENGTH)
        keep(p, x - 3, 5u + b);
    if (x >= 5 && p->size[(x - 5) % N] == PENDING) /* an extended length */
        keep(p, x - 5, 7u + ((size_t)at(p, x - 1) | (size_t)b << 8));
    p->cursor = p->ends[x % N];
    p->open = true;
}

/* The earliest candidate still open, or the last byte if it may begin a header. */
static void advance(sb_parser *p)
{
    while (p->lo < p->now && !open_at(p, p->lo) && !(p->lo + 1u == p->now && at(p, p->lo) == p->header[0]))
        p->lo++;
    p->len = p->now - p->lo;
}

/* The byte now - 1 done with: its sum kept, the byte 5 before it judged
 * (by then every candidate begun at or before it has its length read). */
static void close_byte(sb_parser *p)
{
    uint32_t x = p->now - 1u, j = x - 5u;
    p->ends[x % N] = NONE;
    p->sum[p->now % N] = (uint8_t)(p->sum[x % N] + at(p, x));
    p->open = false;
    advance(p);
    if (x < 5u)
        return;
    if (p->size[j % N] != 0 && (p->size[j % N] & PENDING) == 0 && (int32_t)(j + SPAN(p->size[j % N]) - p->cover) > 0)
        p->cover = j + SPAN(p->size[j % N]);
    p->stray_bytes += (int32_t)(p->cover - j) > 0 ? 0u : 1u; /* in no candidate */
}

/* The candidates ending at byte now - 1 from the cursor on: 1 and the
 * first good one, or 0 with the byte done. */
static int check(sb_parser *p, uint8_t *code, const uint8_t **content, size_t *clen)
{
    uint32_t e = p->now - 1u;
    while (p->cursor != NONE) {
        uint16_t i = p->cursor, size = (uint16_t)SPAN(p->size[i]);
        uint32_t s = e + 1u - size;
        p->cursor = p->next[i];
        if ((uint8_t)(p->sum[e % N] - p->sum[i]) == at(p, e)) {
            p->size[i] |= DONE;
            size_t head = at(p, s + 3u) == SB_EXTENDED_LENGTH ? 6u : 4u;
            p->reach = (int32_t)(e + 1u - p->reach) > 0 ? e + 1u : p->reach;
            p->start = s;
            p->end = e + 1u;
            *code = at(p, s + 2u);
            *content = p->buf + i + head;
            *clen = size - head - 1u;
            return 1;
        }
        /* a bad checksum: counted if it began no later than every open
         * candidate and outside the frames returned */
        advance(p);
        p->bad_frames += p->lo == s && (int32_t)(s - p->reach) >= 0 ? 1u : 0u;
        p->size[i] |= DONE;
    }
    close_byte(p);
    return 0;
}

size_t sb_parser_missing(const sb_parser *p)
{
    size_t held = p->len;
    uint16_t v = held > 0 ? p->size[p->lo % N] : 0;
    if (v == 0 || (v & PENDING) != 0)
        return held < 5 ? 5u - held : 1u;
    return SPAN(v) > held ? SPAN(v) - held : 1u;
}

int sb_parse(sb_parser *p, const uint8_t *data, size_t len, size_t *used, uint8_t *code, const uint8_t **content,
             size_t *clen)
{
    size_t k = 0;
    *used = 0;
    if (p->open && check(p, code, content, clen))
        return 1; /* another frame ending where the one returned last did */
    while (k < len) {
        take(p, data[k++]);
        if (check(p, code, content, clen)) {
            *used = k;
            return 1;
        }
    }
    *used = k;
    return 0;
}
