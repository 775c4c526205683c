/* The rules across a request's fields: what the servo would clamp or not
 * carry out as sent (docs/protocol.md, "Moves"), refused before anything is
 * sent, as servoctl's checks refuse it; and a SyncCommand's records. */
#include "servobus/servobus.h"

#define FIXED_RAMP_MS 20u  /* the ramps of 8 and 13, and of a wheel's run (motion/planning.c) */
#define WHEEL_ACTION 0x7Fu /* MoveOnWheelMode's method: its action, without the direction bit */
#define WHEEL_FOR_A_TIME 3u

/* A move's time must hold both its ramps: the servo stretches it to them. */
typedef struct ramp_rule {
    uint8_t code;
    uint8_t time;     /* the field of the move's time */
    uint8_t acc, dec; /* its ramps' fields; 0: FIXED_RAMP_MS each */
} ramp_rule;

static const ramp_rule RAMP_RULES[] = {
    {SB_PKT_MOVE_WHEEL, 3, 0, 0}, /* a run for value ms */
    {SB_PKT_MOVE_ANGLE, 2, 0, 0},
    {SB_PKT_MOVE_ANGLE_BY_INTERVAL, 2, 3, 4},
    {SB_PKT_MOVE_MULTI_TURN, 2, 0, 0},
    {SB_PKT_MOVE_MULTI_TURN_BY_INTERVAL, 2, 3, 4},
};

static sb_error ramps_held(const sb_packet_desc *p, const ramp_rule *r, const sb_value *v)
{
    int64_t ramps = r->acc != 0 ? v[r->acc].n + v[r->dec].n : 2 * (int64_t)FIXED_RAMP_MS;
    sb_error e = sb_ok();
    if (p->code == SB_PKT_MOVE_WHEEL && ((v[1].n & WHEEL_ACTION) != WHEEL_FOR_A_TIME || v[2].n == 0))
        return e; /* a wheel's stop, run or turns: no time */
    if (v[r->time].n < ramps) {
        e = sb_error_of(SB_E_RANGE, (int)v[0].n, p->code, p->request[r->time].name);
        e.value = v[r->time].n;
        e.least = ramps;
        e.most = p->request[r->time].max;
    }
    return e;
}

/* A value the servo would clamp or not carry out though its field holds
 * it: refused, naming the field and what it takes. */
static sb_error refused(const sb_packet_desc *p, const sb_value *v, size_t field, int64_t value, int64_t least,
                        int64_t most)
{
    sb_error e = sb_error_of(SB_E_RANGE, (int)v[0].n, p->code, p->request[field].name);
    e.value = value;
    e.least = least;
    e.most = most;
    return e;
}

#define DUTY_MAX 32767       /* DriveDuty: -32768 is clamped to -32767, 0 refused (motion/open_loop.c) */
#define UPDATE_WRITE_MAX 24u /* UpdateWrite's data: the bootloader's block (boot_packets.h) */

/* The rules of single fields the schema's ranges do not say. */
static sb_error values_held(const sb_packet_desc *p, const sb_value *v)
{
    if (p->code == SB_PKT_DRIVE_DUTY && (v[1].n == 0 || v[1].n < -DUTY_MAX))
        return refused(p, v, 1, v[1].n, v[1].n == 0 ? 1 : -DUTY_MAX, DUTY_MAX); /* "1..32767" for 0 */
    if (p->code == SB_PKT_MOVE_WHEEL && (v[1].n & WHEEL_ACTION) > WHEEL_FOR_A_TIME)
        return refused(p, v, 1, v[1].n & WHEEL_ACTION, 0, WHEEL_FOR_A_TIME); /* an action the servo takes as stop */
    if (p->code == SB_PKT_UPDATE_WRITE && (v[2].len == 0 || v[2].len > UPDATE_WRITE_MAX)) {
        sb_error e = sb_error_of(SB_E_USAGE, (int)v[0].n, p->code, p->request[2].name);
        e.value = (int64_t)v[2].len; /* the bootloader drops it unanswered */
        e.least = 1;
        e.most = UPDATE_WRITE_MAX;
        return e;
    }
    return sb_ok();
}

#define RECORD_FIELDS 8u /* the most fields a syncable packet has */

/* Each record as its packet's request: its fields' ranges, the rules
 * across them, its servo's ID a servo's and no other record's. */
static sb_error records_hold(const sb_packet_desc *cmd, const sb_value *v)
{
    bool listed[256] = {false};
    sb_value r[RECORD_FIELDS];
    for (size_t k = 0; k < (size_t)v[2].n; k++) {
        sb_error e = sb_decode_request(cmd->code, v[3].bytes + k * (size_t)v[1].n, (size_t)v[1].n, r,
                                       cmd->request_count);
        if (e.status == SB_E_USAGE && e.least < e.most) /* a value beyond its field's range */
            e.status = SB_E_RANGE;
        if (e.status == SB_OK)
            e = sb_check_request(cmd->code, r, cmd->request_count);
        if (e.status == SB_OK && (cmd->flags & SB_PF_ADDRESSED) && (r[0].n > SB_MAX_ID || listed[r[0].n]))
            e = sb_error_of(r[0].n > SB_MAX_ID ? SB_E_BROADCAST : SB_E_DUPLICATE_ID, (int)r[0].n, cmd->code,
                            cmd->request[0].name);
        if (e.status != SB_OK)
            return e;
        listed[r[0].n] = true;
    }
    return sb_ok();
}

/* A SyncCommand: records of a syncable packet at its length, as many as it says, each one that holds. */
static sb_error records_fit(const sb_value *v)
{
    const sb_packet_desc *cmd = sb_packet((uint8_t)v[0].n);
    sb_error e = sb_error_of(SB_E_USAGE, -1, SB_PKT_SYNC_COMMAND, NULL);
    if (cmd == NULL || !(cmd->flags & SB_PF_SYNCABLE) || cmd->length_min != cmd->length_max ||
        cmd->request_count > RECORD_FIELDS) {
        e.field = "cmd";
    } else if (v[1].n != cmd->length_min) { /* "record_len: 2, not 1" */
        e.field = "record_len";
        e.value = v[1].n;
        e.least = e.most = cmd->length_min;
    } else if (v[2].n == 0) {
        e.field = "count";
        e.least = 1;
        e.most = 255;
    } else if (v[3].len != (size_t)v[1].n * (size_t)v[2].n || v[3].bytes == NULL) {
        e.field = "records"; /* "records: 4, not 3" (bytes) */
        e.value = (int64_t)v[3].len;
        e.least = e.most = v[1].n * v[2].n;
    }
    return e.field != NULL ? e : records_hold(cmd, v);
}

/* Each number within its field's range (an item's value is the encoder's to check). */
static sb_error ranges_held(const sb_packet_desc *p, const sb_value *v)
{
    for (size_t k = 0; k < p->request_count; k++) {
        const sb_field_desc *f = &p->request[k];
        bool number = f->type != SB_ITEM && f->type != SB_USER_AREA && f->type != SB_BYTES;
        if (number && (v[k].n < f->min || v[k].n > f->max)) {
            bool named = (p->flags & SB_PF_ADDRESSED) && k > 0; /* its ID within its own range */
            sb_error e = sb_error_of(SB_E_RANGE, named ? (int)v[0].n : -1, p->code, f->name);
            e.value = v[k].n;
            e.least = f->min;
            e.most = f->max;
            return e;
        }
    }
    return sb_ok();
}

sb_error sb_check_request(uint8_t code, const sb_value *v, size_t count)
{
    const sb_packet_desc *p = sb_packet(code);
    sb_error e;
    if (p == NULL)
        return sb_error_of(SB_E_UNKNOWN_PACKET, -1, code, NULL);
    if (count != p->request_count) { /* "fields: 3, not 2" */
        e = sb_error_of(SB_E_USAGE, -1, code, "fields");
        e.value = (int64_t)count;
        e.least = e.most = p->request_count;
        return e;
    }
    e = ranges_held(p, v); /* first: the rules' sums stay within int64_t */
    if (e.status != SB_OK)
        return e;
    if (code == SB_PKT_SYNC_COMMAND)
        return records_fit(v);
    e = values_held(p, v);
    if (e.status != SB_OK)
        return e;
    for (size_t k = 0; k < sizeof RAMP_RULES / sizeof RAMP_RULES[0]; k++)
        if (RAMP_RULES[k].code == code)
            return ramps_held(p, &RAMP_RULES[k], v);
    return sb_ok();
}
