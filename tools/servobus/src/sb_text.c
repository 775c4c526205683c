/* Errors in words: the servo, the packet, the field, what went wrong and
 * the value and range it carries. */
#include <errno.h>
#include <string.h>

#include "servobus/servobus.h"

#if defined(__unix__) || defined(__APPLE__)
#define SB_HAS_STRERROR 1 /* a host's C library names errno's values; a microcontroller's may not */
#endif

typedef struct text {
    char *buf;
    size_t cap, len;
} text;

static void put(text *t, const char *s)
{
    while (*s != '\0') {
        if (t->len + 1 < t->cap)
            t->buf[t->len++] = *s;
        s++;
    }
    if (t->cap > 0)
        t->buf[t->len < t->cap ? t->len : t->cap - 1] = '\0';
}

static void put_number(text *t, int64_t n)
{
    char digits[24];
    size_t k = sizeof digits - 1;
    uint64_t u = n < 0 ? 0u - (uint64_t)n : (uint64_t)n;
    digits[k] = '\0';
    do {
        digits[--k] = (char)('0' + u % 10u);
        u /= 10u;
    } while (u > 0);
    if (n < 0)
        digits[--k] = '-';
    put(t, digits + k);
}

static const char *const WHAT[] = {
    "ok",
    "out of range",
    "not allowed",
    "not a packet of the protocol",
    "refused",
    "the buffer is too small",
    "no answer",
    "an answer with a bad checksum",
    "a bad answer",
    "the link failed",
    "listed twice",
    "is the broadcast ID: no servo answers it or carries it out",
};

static bool named(const sb_error *e, const char *field)
{
    return e->field != NULL && strcmp(e->field, field) == 0;
}

static bool assign_unknown(const sb_error *e)
{
    return e->status == SB_E_NO_ANSWER && e->packet == SB_PKT_ASSIGN_ID && named(e, "serial");
}

/* ": 33 is beyond 1..32", or ": 8, not 1" where one value is right. */
static void put_range(text *t, const sb_error *e)
{
    bool servos = e->status == SB_E_USAGE && named(e, "ids");
    bool bytes = e->status == SB_E_BAD_ANSWER && (named(e, "length") || named(e, "data"));
    put(t, ": ");
    put_number(t, e->value);
    put(t, servos ? " servos" : bytes ? " bytes" : "");
    if (e->least == e->most) {
        put(t, ", not ");
        put_number(t, e->least);
        return;
    }
    put(t, " is beyond ");
    put_number(t, e->least);
    put(t, "..");
    put_number(t, e->most);
    put(t, servos && e->most == SB_MAX_SERVOS ? " (SB_MAX_SERVOS)" : "");
}

/* "no data item 200 in the schema", "item 1 (voltage_mv) is read-only" */
static void put_item(text *t, const sb_error *e)
{
    const sb_item_desc *item = e->value >= 0 && e->value <= 255 ? sb_item((uint8_t)e->value) : NULL;
    put(t, item == NULL ? ": no data item " : ": item ");
    put_number(t, e->value);
    if (item == NULL) {
        put(t, " in the schema");
        return;
    }
    put(t, " (");
    put(t, item->name);
    put(t, item->access == SB_ACCESS_READ ? ") is read-only" : ") is reserved");
}

/* A stream's step beyond the servo's top speed at the stream's period. */
static void put_step(text *t)
{
    put(t, ": over ");
    put_number(t, sb_packet(SB_PKT_STREAM_SETPOINT)->request[2].max / 10);
    put(t, " deg/s at this period: use a longer period or a smaller step");
}

/* A loop's period shorter than its cycle's bytes on the wire (sb_loop_init). */
static void put_wire(text *t, const sb_error *e)
{
    put(t, ": ");
    put_number(t, e->value);
    put(t, " ms is shorter than the wire's cycle at this baud rate (sb_cycle_bytes): at least ");
    put_number(t, e->least);
    put(t, " ms");
}

size_t sb_error_text(const sb_error *e, char *buf, size_t cap)
{
    text t = {buf, cap, 0};
    const sb_packet_desc *p = e->packet != 0 ? sb_packet(e->packet) : NULL;
    bool ranged = e->value != 0 || e->least != 0 || e->most != 0;
    put(&t, "");
    if (e->servo >= 0) {
        put(&t, "servo ");
        put_number(&t, e->servo);
        put(&t, ": ");
    }
    if (p != NULL) {
        put(&t, p->name);
        put(&t, ": ");
    } else if (e->packet != 0) {
        put(&t, "packet ");
        put_number(&t, e->packet);
        put(&t, ": ");
    }
    if (assign_unknown(e)) { /* AssignId at 255: only the servo with the serial answers */
        put(&t, "no servo has serial ");
        put_number(&t, e->value);
        put(&t, " (item 8): none answered (is the servo on the bus, at this baud rate?)");
        return t.len;
    }
    if (e->field != NULL) {
        put(&t, e->field);
        put(&t, " ");
    }
    put(&t, (size_t)e->status < sizeof WHAT / sizeof WHAT[0] ? WHAT[e->status] : "unknown error");
    if (e->status == SB_E_RANGE) {
        put_range(&t, e);
        if (e->packet == SB_PKT_STREAM_SETPOINT && named(e, "angle step"))
            put_step(&t);
        put(&t, "; nothing was sent");
    } else if (e->status == SB_E_USAGE && named(e, "period_ms") && e->least > 1 && e->value < e->least) {
        put_wire(&t, e);
    } else if (e->status == SB_E_USAGE && ranged) {
        put_range(&t, e);
    } else if (e->status == SB_E_USAGE && e->field != NULL && strcmp(e->field, "cmd") == 0) {
        put(&t, ": not a packet SyncCommand carries");
    } else if (e->status == SB_E_USAGE && named(e, "loop")) {
        put(&t, ": sb_loop_init refused it; nothing was sent");
    } else if (e->status == SB_E_BAD_ANSWER && ranged) {
        put_range(&t, e);
    } else if (e->status == SB_E_DUPLICATE_ID || e->status == SB_E_BROADCAST) {
        put(&t, "; nothing was sent");
    } else if (e->status == SB_E_NO_ANSWER) {
        put(&t, " in time (is it on the bus, at this baud rate? two servos at one ID garble each other)");
    } else if (e->status == SB_E_BAD_CHECKSUM) {
        put(&t, " (noise on the line, or two servos at one ID answering together)");
    } else if (e->status == SB_E_LINK) {
        put(&t, " (errno ");
        put_number(&t, e->os_error);
#ifdef SB_HAS_STRERROR
        put(&t, ": ");
        put(&t, strerror(e->os_error));
#endif
        put(&t, ")");
#ifdef EBUSY
        if (e->os_error == EBUSY)
            put(&t, ": another program holds the bus (a simulator's other client): close it, then try again");
#endif
    } else if (e->status == SB_E_UNKNOWN_ITEM) {
        put_item(&t, e);
    } else if (e->status == SB_E_SPACE && e->value > 0) {
        put(&t, ": ");
        put_number(&t, e->value);
        put(&t, " bytes needed, ");
        put_number(&t, e->most);
        put(&t, " given");
    }
    return t.len;
}
