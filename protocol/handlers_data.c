/* Packets that read or write the register file: 1-6 and Monitor (22). */
#include <stddef.h>
#include <string.h>

#include "registers/data_table.h"
#include "registers/field_ranges.h"
#include "protocol/packet_table.h"
#include "protocol/wire.h"

enum packet_outcome handle_ping(const struct packet_call *c, struct response *r)
{
    (void)c;
    r->length = 1;
    return OUTCOME_OK;
}

/* A change to the user or drive area is kept only once it is durable (the
 * store's persist hook) and not refused; otherwise both go back to what
 * they were. */
static bool keep_change(const struct packet_call *c, const struct user_config *before, bool refused)
{
    struct dispatcher *d = c->d;
    if (refused || (d->persist != NULL && !d->persist(d->persist_ctx, &d->regs->user))) {
        d->regs->user = *before;
        return false;
    }
    c->result->config_changed = true;
    return true;
}

/* The same for a change of many items, which may have changed nothing. */
static bool commit_user(const struct packet_call *c, const struct user_config *before)
{
    c->d->regs->store.write_refused = 0;
    return memcmp(before, &c->d->regs->user, sizeof *before) == 0 || keep_change(c, before, false);
}

enum packet_outcome handle_reset_user_data(const struct packet_call *c, struct response *r)
{
    const struct user_config before = c->d->regs->user;
    user_config_reset(&c->d->regs->user);
    return answer_result(r, commit_user(c, &before));
}

enum packet_outcome handle_read_data(const struct packet_call *c, struct response *r)
{
    r->content[1] = c->content[1];
    c->d->regs->firmware.limiter = motion_limiter(c->d->motion); /* live: as read */
    c->d->regs->firmware.encoder_count = motion_encoder_count(c->d->motion);
    uint8_t size = data_table_read(c->d->regs, c->content[1], &r->content[2]);
    r->length = (uint8_t)(2u + size);
    return OUTCOME_OK;
}

/* One item written as WriteData does: true once it holds the value, durably. */
static bool write_item(const struct packet_call *c, uint8_t id, const uint8_t *data, uint8_t length)
{
    struct user_config before;
    enum data_write_result w = data_table_write(c->d->regs, id, data, length, &before);
    /* A drive item that would make a stable loop unstable is put back
     * before the store sees it (keep_change); ReadStore says why (bit 2).
     * One already unstable (an older firmware's) takes any write: the way
     * out. */
    bool unstable = w == DATA_WRITE_CHANGED && id >= DRIVE_FIRST &&
                    !drive_items_stable(&c->d->regs->user) && drive_items_stable(&before);
    c->d->regs->store.write_refused = unstable ? STORE_UNSTABLE : 0u;
    bool ok = w == DATA_WRITE_SAME || (w == DATA_WRITE_CHANGED && keep_change(c, &before, unstable));
    if (w == DATA_WRITE_CHANGED && id >= DRIVE_FIRST) { /* kept or put back: the feed-forward follows */
        motion_drive_train_changed(c->d->motion);
    }
    return ok;
}

enum packet_outcome handle_write_data(const struct packet_call *c, struct response *r)
{
    bool ok = write_item(c, c->content[1], &c->content[2], (uint8_t)(c->length - 2u));
    r->content[1] = c->content[1];
    r->content[2] = ok ? 1u : 0u;
    r->length = 3;
    return ok ? OUTCOME_OK : OUTCOME_FAILED;
}

enum packet_outcome handle_read_batch(const struct packet_call *c, struct response *r)
{
    user_config_encode(&c->d->regs->user, &r->content[1]);
    r->length = 1u + USER_AREA_SIZE;
    return OUTCOME_OK;
}

enum packet_outcome handle_write_batch(const struct packet_call *c, struct response *r)
{
    const struct user_config before = c->d->regs->user;
    bool ok = user_config_decode(&c->d->regs->user, &c->content[1], USER_AREA_SIZE) && commit_user(c, &before);
    return answer_result(r, ok);
}

enum { READ_STORE_ANSWER_LENGTH = 34 };
_Static_assert(READ_STORE_ANSWER_LENGTH == 2 + 8 * 4 && READ_STORE_ANSWER_LENGTH <= RESPONSE_CONTENT_MAX &&
                   offsetof(struct response, content) == sizeof(uint32_t) &&
                   __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
               "ReadStore fits a response, its content whole words, little-endian");

enum packet_outcome handle_read_store(const struct packet_call *c, struct response *r)
{
    const struct store_health *h = &c->d->regs->store;
    const uint32_t counts[] = {h->records, h->page_erases, h->rated_cycles, h->budget,
                               h->op_seconds, h->failures, h->answers_dropped, h->bytes_lost};
    /* ID and flags, then the counts from content byte 2: a word of the
     * content holds one's high half and the next one's low half (the M0
     * stores a byte a store where a count is put at a time). */
    uint32_t *w = &r->words[1];
    uint32_t half = r->content[0] | (uint32_t)(h->write_refused ? h->write_refused : h->flags) << 8;
    for (unsigned i = 0; i < sizeof counts / sizeof counts[0]; i++) {
        w[i] = half | counts[i] << 16;
        half = counts[i] >> 16;
    }
    w[8] = half;
    r->length = READ_STORE_ANSWER_LENGTH;
    return OUTCOME_OK;
}

enum packet_outcome handle_monitor(const struct packet_call *c, struct response *r)
{
    const struct status_area *s = &c->d->regs->status;
    struct motion_angle angle;
    motion_read_angle(c->d->motion, &angle);
    uint32_t current = s->current_ma;
    uint32_t temperature = s->temperature_adc;
    uint32_t turn_angle = (uint32_t)angle.multi_turn_decideg;
    /* The fields a content word at a time (as ReadStore's): voltage at
     * byte 1, current 3, power 5, temperature 7, status 9, angle 10, turns
     * 14. */
    uint32_t *w = &r->words[1];
    w[0] = r->content[0] | (uint32_t)s->voltage_mv << 8 | current << 24;
    w[1] = current >> 8 | (uint32_t)s->power_mw << 8 | temperature << 24;
    w[2] = temperature >> 8 | (uint32_t)s->status << 8 | turn_angle << 16;
    w[3] = turn_angle >> 16 | (uint32_t)(uint16_t)angle.turns << 16;
    r->length = 16;
    return OUTCOME_OK;
}

/* AssignId (docs/packets.md): sent to every servo (ID 0xFF) and taken by
 * the one with the serial number, so it reaches one servo among several
 * that share an ID; the others stay silent. The ID is written as WriteData
 * of item 34 writes it. */
/* AssignId's new ID is written as item 34, and refused beyond its range. */
_Static_assert(FIELD_ASSIGN_ID_NEW_ID_MIN == ITEM_SERVO_ID_MIN && FIELD_ASSIGN_ID_NEW_ID_MAX == ITEM_SERVO_ID_MAX,
               "AssignId's new ID ranges as item 34");

enum packet_outcome handle_assign_id(const struct packet_call *c, struct response *r)
{
    if (le_get_u32(&c->content[1]) != c->d->regs->status.serial_number) {
        return OUTCOME_NONE;
    }
    bool ok = write_item(c, ITEM_SERVO_ID, &c->content[5], 1u);
    r->content[0] = c->d->regs->user.servo_id;
    r->content[1] = ok ? 1u : 0u;
    r->length = 2;
    return ok ? OUTCOME_OK : OUTCOME_FAILED;
}
