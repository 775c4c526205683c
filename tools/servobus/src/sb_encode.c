/* A request's encoding: its fields against their ranges (sb_codec.c),
 * then the rules its fields keep together (sb_rules.c), which the servo
 * would otherwise clamp or act on silently; and SyncCommand's frame. The
 * layer between the codec and the bus: the codec and the rules know
 * nothing of each other. */
#include <string.h>

#include "servobus/servobus.h"
#include "servobus/sb_codec_inner.h"

sb_error sb_encode_content(uint8_t code, const sb_value *v, size_t count, uint8_t *out, size_t cap, size_t *len)
{
    sb_error e = sb_encode_fields(code, true, v, count, out, cap, len);
    return e.status == SB_OK ? sb_check_request(code, v, count) : e;
}

sb_error sb_encode_request(uint8_t code, const sb_value *v, size_t count, uint8_t *frame, size_t cap, size_t *len)
{
    sb_error e = sb_encode_frame(code, true, v, count, frame, cap, len);
    return e.status == SB_OK ? sb_check_request(code, v, count) : e;
}

/* A number the call does not allow: value, and the range it must be in. */
static sb_error usage_of(uint8_t code, const char *field, int64_t value, int64_t least, int64_t most)
{
    sb_error e = sb_error_of(SB_E_USAGE, -1, code, field);
    e.value = value;
    e.least = least;
    e.most = most;
    return e;
}

sb_error sb_sync_frame(uint8_t cmd, const uint8_t *records, size_t record_len, size_t count, uint8_t *frame,
                       size_t cap, size_t *len)
{
    sb_value v[4] = {{cmd, NULL, 0}, {0, NULL, 0}, {0, NULL, 0}, {0, NULL, 0}};
    size_t clen = 3u + record_len * count;
    sb_error e;
    if (record_len > 255u)
        return usage_of(SB_PKT_SYNC_COMMAND, "record_len", (int64_t)record_len, 1, 255);
    if (count > 255u)
        return usage_of(SB_PKT_SYNC_COMMAND, "count", (int64_t)count, 1, 255);
    v[1].n = (int64_t)record_len;
    v[2].n = (int64_t)count;
    v[3].bytes = records;
    v[3].len = record_len * count;
    e = sb_check_request(SB_PKT_SYNC_COMMAND, v, 4); /* what the typed encoder checks too */
    if (e.status != SB_OK)
        return e;
    if (7u + clen > cap) { /* "40 bytes needed, 32 given" */
        e = sb_error_of(SB_E_SPACE, -1, SB_PKT_SYNC_COMMAND, NULL);
        e.value = (int64_t)(7u + clen);
        e.most = (int64_t)cap;
        return e;
    }
    memmove(frame + 9, records, record_len * count); /* the content at 6, then moved to its place */
    frame[6] = cmd;
    frame[7] = (uint8_t)record_len;
    frame[8] = (uint8_t)count;
    return sb_frame(true, SB_PKT_SYNC_COMMAND, frame + 6, clen, frame, cap, len);
}
