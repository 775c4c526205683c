/* The codec: any packet's request or answer from the schema's tables
 * (sb_schema.c), its fields checked against their ranges; the rules a
 * request's fields keep together are sb_encode.c's, above this. */
#include <string.h>

#include "servobus/servobus.h"
#include "servobus/sb_codec_inner.h"

#define fail sb_error_of

sb_error sb_error_of(sb_status status, int servo, uint8_t packet, const char *field)
{
    sb_error e = sb_ok();
    e.status = status;
    e.servo = (int16_t)servo;
    e.packet = packet;
    e.field = field;
    return e;
}

sb_transport sb_transport_make(void *ctx, int (*write)(void *, const uint8_t *, size_t),
                               int (*read)(void *, uint8_t *, size_t, size_t, uint32_t), uint64_t (*now_us)(void *))
{
    sb_transport t;
    t.ctx = ctx;
    t.write = write;
    t.read = read;
    t.now_us = now_us;
    return t;
}

sb_error sb_ok(void)
{
    sb_error e;
    memset(&e, 0, sizeof e);
    e.servo = -1;
    return e;
}

const sb_packet_desc *sb_packet(uint8_t code)
{
    for (size_t k = 0; k < SB_PACKET_COUNT; k++)
        if (sb_packets[k].code == code)
            return &sb_packets[k];
    return NULL;
}

const sb_item_desc *sb_item(uint8_t id)
{
    for (size_t k = 0; k < SB_ITEM_COUNT; k++)
        if (sb_items[k].id == id)
            return &sb_items[k];
    return NULL;
}

uint8_t sb_checksum(const uint8_t *data, size_t len)
{
    unsigned sum = 0;
    for (size_t k = 0; k < len; k++)
        sum += data[k];
    return (uint8_t)sum;
}

static size_t type_size(uint8_t type)
{
    switch (type) {
    case SB_U8:
        return 1;
    case SB_U16:
    case SB_I16:
        return 2;
    case SB_U32:
    case SB_I32:
        return 4;
    default:
        return 0;
    }
}

static void put_le(uint8_t *out, int64_t value, size_t size)
{
    uint64_t u = (uint64_t)value;
    for (size_t k = 0; k < size; k++)
        out[k] = (uint8_t)(u >> (8u * k));
}

static int64_t get_le(const uint8_t *in, size_t size, bool is_signed)
{
    uint64_t u = 0;
    for (size_t k = 0; k < size; k++)
        u |= (uint64_t)in[k] << (8u * k);
    if (is_signed && size < 8 && (u >> (8u * size - 1u)) & 1u)
        u |= ~(uint64_t)0 << (8u * size);
    return (int64_t)u;
}

sb_error sb_check_ids(const uint8_t *ids, size_t count, uint8_t code)
{
    for (size_t k = 0; k < count; k++) {
        if (ids[k] > SB_MAX_ID)
            return fail(SB_E_BROADCAST, ids[k], code, "ids");
        for (size_t j = 0; j < k; j++)
            if (ids[j] == ids[k])
                return fail(SB_E_DUPLICATE_ID, ids[k], code, "ids");
    }
    return sb_ok();
}

/* The servo a packet's fields name: an addressed packet's first field,
 * if it is an ID at all (an error about ID 256 names no servo 256). */
static int servo_of(const sb_packet_desc *p, const sb_value *v, size_t count)
{
    return (p->flags & SB_PF_ADDRESSED) && count > 0 && v[0].n >= 0 && v[0].n <= 255 ? (int)v[0].n : -1;
}

static sb_error out_of_range(int servo, uint8_t code, const char *field, int64_t value, int64_t least, int64_t most)
{
    sb_error e = fail(SB_E_RANGE, servo, code, field);
    e.value = value;
    e.least = least;
    e.most = most;
    return e;
}

/* The item a data field holds (the field before it, data_id). */
static const sb_item_desc *item_of(const sb_value *v, size_t k)
{
    return k > 0 ? sb_item((uint8_t)v[k - 1].n) : NULL;
}

/* SB_E_SPACE: "40 bytes needed, 32 given". */
static sb_error no_space(int servo, uint8_t code, size_t needed, size_t given)
{
    sb_error e = fail(SB_E_SPACE, servo, code, NULL);
    e.value = (int64_t)needed;
    e.most = (int64_t)given;
    return e;
}

/* The content's bytes the fields' values make. */
static size_t content_size(const sb_field_desc *f, size_t fields, const sb_value *v)
{
    size_t n = 0;
    for (size_t k = 0; k < fields; k++) {
        const sb_item_desc *item = f[k].type == SB_ITEM ? item_of(v, k) : NULL;
        n += f[k].type == SB_ITEM ? (item != NULL ? item->size : 0u)
             : f[k].type == SB_USER_AREA || f[k].type == SB_BYTES ? v[k].len
                                                                   : type_size(f[k].type);
    }
    return n;
}

static sb_error encode_fields(const sb_packet_desc *p, bool request, const sb_value *v, size_t count, uint8_t *out,
                              size_t cap, size_t *len)
{
    const sb_field_desc *f = request ? p->request : p->answer;
    size_t fields = request ? p->request_count : p->answer_count;
    int servo = servo_of(p, v, count);
    size_t at = 0;
    if (count != fields) { /* "fields: 3, not 4" */
        sb_error e = fail(SB_E_USAGE, servo, p->code, "fields");
        e.value = (int64_t)count;
        e.least = e.most = (int64_t)fields;
        return e;
    }
    /* A servo takes a packet sent to the broadcast ID only if it is a broadcast one (and then never answers). */
    if (request && servo == SB_BROADCAST_ID && !(p->flags & SB_PF_BROADCAST))
        return fail(SB_E_BROADCAST, servo, p->code, f[0].name);
    for (size_t k = 0; k < fields; k++) {
        size_t size = type_size(f[k].type);
        int64_t least = f[k].min, most = f[k].max;
        bool number = f[k].type != SB_USER_AREA && f[k].type != SB_BYTES;
        if (f[k].type == SB_ITEM) {
            const sb_item_desc *item = item_of(v, k);
            if (item == NULL || (request ? item->access != SB_ACCESS_READ_WRITE : item->access == SB_ACCESS_RESERVED)) {
                sb_error e = fail(SB_E_UNKNOWN_ITEM, servo, p->code, k > 0 ? f[k - 1].name : f[k].name);
                e.value = k > 0 ? v[k - 1].n : 0; /* data_id's: the item refused */
                return e;
            }
            size = item->size;
            least = item->min;
            most = item->max;
            if (!request) { /* what a servo reads back: the item's type's range */
                most = item->is_signed ? (INT64_C(1) << (8u * size - 1u)) - 1 : (INT64_C(1) << (8u * size)) - 1;
                least = item->is_signed ? -most - 1 : 0;
            }
        } else if (!number) {
            size = v[k].len;
            if ((f[k].type == SB_USER_AREA && size != SB_USER_AREA_SIZE) || (size > 0 && v[k].bytes == NULL))
                return fail(SB_E_USAGE, servo, p->code, f[k].name);
        }
        if (number && (v[k].n < least || v[k].n > most))
            return out_of_range(servo, p->code, f[k].name, v[k].n, least, most);
        if (request && strcmp(f[k].name, "data_id") == 0 && sb_item((uint8_t)v[k].n) == NULL) {
            sb_error e = fail(SB_E_UNKNOWN_ITEM, servo, p->code, f[k].name); /* ReadData's, WriteData's */
            e.value = v[k].n;
            return e;
        }
        if (at + size > cap)
            return no_space(servo, p->code, content_size(f, fields, v), cap);
        if (number)
            put_le(out + at, v[k].n, size);
        else if (size > 0)
            memcpy(out + at, v[k].bytes, size);
        at += size;
    }
    if (request && (at < p->length_min || (p->length_max != 0xFFFFu && at > p->length_max))) {
        sb_error e = fail(SB_E_USAGE, servo, p->code, "length"); /* the content's bytes */
        e.value = (int64_t)at;
        e.least = p->length_min;
        e.most = p->length_max;
        return e;
    }
    *len = at;
    return sb_ok();
}

sb_error sb_encode_fields(uint8_t code, bool request, const sb_value *v, size_t count, uint8_t *out, size_t cap,
                          size_t *len)
{
    const sb_packet_desc *p = sb_packet(code);
    if (p == NULL)
        return fail(SB_E_UNKNOWN_PACKET, -1, code, NULL);
    return encode_fields(p, request, v, count, out, cap, len);
}

sb_error sb_frame(bool request, uint8_t code, const uint8_t *content, size_t clen, uint8_t *frame, size_t cap,
                  size_t *len)
{
    size_t head = clen >= SB_EXTENDED_LENGTH ? 6u : 4u;
    if (clen > 0xFFFFu || head + clen + 1u > cap)
        return no_space(-1, code, head + clen + 1u, cap);
    memmove(frame + head, content, clen); /* content may already lie in frame */
    frame[0] = request ? SB_REQUEST_HEADER_0 : SB_RESPONSE_HEADER_0;
    frame[1] = request ? SB_REQUEST_HEADER_1 : SB_RESPONSE_HEADER_1;
    frame[2] = code;
    if (head == 6u) {
        frame[3] = SB_EXTENDED_LENGTH;
        frame[4] = (uint8_t)clen;
        frame[5] = (uint8_t)(clen >> 8);
    } else {
        frame[3] = (uint8_t)clen;
    }
    frame[head + clen] = sb_checksum(frame, head + clen);
    *len = head + clen + 1u;
    return sb_ok();
}

static sb_error encode_frame(uint8_t code, bool request, const sb_value *v, size_t count, uint8_t *frame, size_t cap,
                             size_t *len)
{
    const sb_packet_desc *p = sb_packet(code);
    size_t clen = 0;
    sb_error e;
    if (p == NULL)
        return fail(SB_E_UNKNOWN_PACKET, -1, code, NULL);
    if (cap < 5u) /* not even a frame's header and checksum */
        return no_space(servo_of(p, v, count), code,
                        5u + (count == (request ? p->request_count : p->answer_count)
                                  ? content_size(request ? p->request : p->answer, count, v)
                                  : 0u),
                        cap);
    /* The content goes where a short frame's lies, then moves if extended. */
    e = encode_fields(p, request, v, count, frame + 4, cap - 5u, &clen);
    if (e.status == SB_E_SPACE) { /* the frame's bytes, not the content's */
        e.value += (size_t)e.value >= SB_EXTENDED_LENGTH ? 7 : 5;
        e.most = (int64_t)cap;
    }
    if (e.status != SB_OK)
        return e;
    e = sb_frame(request, code, frame + 4, clen, frame, cap, len);
    e.servo = (int16_t)servo_of(p, v, count);
    return e;
}

sb_error sb_encode_frame(uint8_t code, bool request, const sb_value *v, size_t count, uint8_t *frame, size_t cap,
                         size_t *len)
{
    return encode_frame(code, request, v, count, frame, cap, len);
}

sb_error sb_encode_answer(uint8_t code, const sb_value *v, size_t count, uint8_t *frame, size_t cap, size_t *len)
{
    return encode_frame(code, false, v, count, frame, cap, len);
}

/* The fixed bytes of the fields from k on. */
static size_t fixed_after(const sb_field_desc *f, size_t fields, size_t k)
{
    size_t n = 0;
    for (size_t j = k; j < fields; j++)
        n += f[j].type == SB_USER_AREA ? SB_USER_AREA_SIZE : type_size(f[j].type);
    return n;
}

static sb_error bad_length(sb_status bad, int servo, uint8_t code, const char *field, size_t got, size_t want)
{
    sb_error e = fail(bad, servo, code, field);
    e.value = (int64_t)got;
    e.least = e.most = (int64_t)want;
    return e;
}

static sb_error decode_fields(const sb_packet_desc *p, bool request, const uint8_t *in, size_t len, sb_value *v,
                              size_t count)
{
    const sb_field_desc *f = request ? p->request : p->answer;
    size_t fields = request ? p->request_count : p->answer_count;
    int servo = (p->flags & SB_PF_ADDRESSED) && len > 0 ? in[0] : -1;
    size_t at = 0;
    sb_status bad = request ? SB_E_USAGE : SB_E_BAD_ANSWER;
    if (count != fields) { /* "fields: 3, not 2" */
        sb_error e = fail(SB_E_USAGE, servo, p->code, "fields");
        e.value = (int64_t)count;
        e.least = e.most = (int64_t)fields;
        return e;
    }
    memset(v, 0, count * sizeof *v);
    for (size_t k = 0; k < fields; k++) {
        size_t size = type_size(f[k].type);
        bool is_signed = f[k].type == SB_I16 || f[k].type == SB_I32;
        if (f[k].type == SB_USER_AREA) {
            size = SB_USER_AREA_SIZE;
        } else if (f[k].type == SB_BYTES || f[k].type == SB_ITEM) {
            size_t rest = fixed_after(f, fields, k + 1);
            size = len >= at + rest ? len - at - rest : 0;
        }
        if (at + size > len) /* "length: 5 bytes, not 6": the fixed fields' bytes */
            return bad_length(bad, servo, p->code, "length", len, at + size + fixed_after(f, fields, k + 1));
        if (f[k].type == SB_ITEM) {
            const sb_item_desc *item = item_of(v, k);
            size_t want = item != NULL && item->access != SB_ACCESS_RESERVED ? item->size : 0;
            if (size != want) /* "data: 3 bytes, not 4": the item's size */
                return bad_length(bad, servo, p->code, f[k].name, size, want);
            is_signed = item != NULL && item->is_signed;
        }
        v[k].len = size;
        if (f[k].type == SB_USER_AREA || f[k].type == SB_BYTES) {
            v[k].bytes = in + at;
        } else if (size > 0) {
            v[k].n = get_le(in + at, size, is_signed);
            if (f[k].type != SB_ITEM && (v[k].n < f[k].min || v[k].n > f[k].max)) {
                sb_error e = fail(bad, servo, p->code, f[k].name);
                e.value = v[k].n;
                e.least = f[k].min;
                e.most = f[k].max;
                return e;
            }
        }
        at += size;
    }
    if (at != len)
        return bad_length(bad, servo, p->code, "length", len, at);
    return sb_ok();
}

sb_error sb_decode_answer(uint8_t code, const uint8_t *content, size_t len, sb_value *v, size_t count)
{
    const sb_packet_desc *p = sb_packet(code);
    if (p == NULL)
        return fail(SB_E_UNKNOWN_PACKET, -1, code, NULL);
    return decode_fields(p, false, content, len, v, count);
}

sb_error sb_decode_request(uint8_t code, const uint8_t *content, size_t len, sb_value *v, size_t count)
{
    const sb_packet_desc *p = sb_packet(code);
    if (p == NULL)
        return fail(SB_E_UNKNOWN_PACKET, -1, code, NULL);
    return decode_fields(p, true, content, len, v, count);
}

size_t sb_answer_frame_size(uint8_t code)
{
    const sb_packet_desc *p = sb_packet(code);
    size_t n = 0;
    if (p == NULL)
        return 0;
    for (size_t k = 0; k < p->answer_count; k++) {
        if (p->answer[k].type == SB_ITEM || p->answer[k].type == SB_BYTES)
            return 0;
        n += p->answer[k].type == SB_USER_AREA ? SB_USER_AREA_SIZE : type_size(p->answer[k].type);
    }
    return n + 5u;
}
