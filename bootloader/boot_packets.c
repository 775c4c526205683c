#include "bootloader/boot_packets.h"

#include <stddef.h>

#include "protocol/packet_codes.h"
#include "protocol/update_status.h"
#include "protocol/wire.h"
#include "bootloader/slot_write.h"

struct call {
    struct bootloader *b;
    const uint8_t *content;
    uint16_t length;
};

static uint8_t on_ping(const struct call *c, struct response *r)
{
    (void)c;
    (void)r;
    return 1;
}

static uint8_t on_enter(const struct call *c, struct response *r)
{
    (void)c;
    r->content[1] = 1; /* here already */
    r->content[2] = 0;
    return 3;
}

enum app_image_verdict bootloader_check(struct bootloader *b, struct app_image_info *info)
{
    enum app_image_verdict verdict = app_image_check(b->slot, b->board, info);
    b->verdict = (uint8_t)verdict;
    b->version = info->version;
    b->checked = 1;
    return verdict;
}

static uint8_t on_erase(const struct call *c, struct response *r)
{
    c->b->checked = 0;
    enum slot_write_result w = slot_erase_page(c->b->slot, le_get_u16(&c->content[1]));
    r->content[1] = w == SLOT_WRITE_OK;
    r->content[2] = (uint8_t)w;
    return 3;
}

static uint8_t on_write(const struct call *c, struct response *r)
{
    uint16_t n = (uint16_t)(c->length - 9u);
    c->b->checked = 0;
    enum slot_write_result w = slot_write(c->b->slot, le_get_u32(&c->content[1]), &c->content[5],
                                          n, le_get_u32(&c->content[5u + n]));
    r->content[1] = w == SLOT_WRITE_OK;
    r->content[2] = (uint8_t)w;
    return 3;
}

static uint8_t on_verify(const struct call *c, struct response *r)
{
    struct app_image_info info;
    r->content[1] = (uint8_t)bootloader_check(c->b, &info);
    le_put_u32(&r->content[2], info.size);
    le_put_u32(&r->content[6], info.crc);
    le_put_u16(&r->content[10], info.version);
    le_put_u16(&r->content[12], info.board);
    return 14;
}

static uint8_t on_boot(const struct call *c, struct response *r)
{
    struct app_image_info info;
    bool valid = bootloader_check(c->b, &info) == APP_IMAGE_VALID;
    c->b->boot_now = valid;
    r->content[1] = valid;
    return 2;
}

static uint8_t on_status(const struct call *c, struct response *r)
{
    const struct app_slot *slot = c->b->slot;
    if (!c->b->checked) {
        struct app_image_info info;
        (void)bootloader_check(c->b, &info);
    }
    const struct update_status status = {
        .mode = UPDATE_MODE_BOOTLOADER,
        .bootloader_version = BOOTLOADER_VERSION,
        .image_verdict = c->b->verdict,
        .app_version = c->b->version,
        .board = c->b->board,
        .page_size = (uint16_t)slot->flash->page_size,
        .pages = (uint16_t)slot->pages,
        .write_block = (uint8_t)slot->flash->write_block,
        .write_max = UPDATE_WRITE_MAX,
    };
    return update_status_encode(&status, r->content);
}

/* Eight bytes a row: every length here fits a byte. */
struct boot_packet_desc {
    uint8_t (*handle)(const struct call *c, struct response *r); /* answer length */
    uint8_t code;
    uint8_t min_length;
    uint8_t max_length;
};

static const struct boot_packet_desc packets[] = {
    {on_ping, PKT_PING, 1, 1},
    {on_enter, PKT_UPDATE_ENTER, 1, 1},
    {on_erase, PKT_UPDATE_ERASE, 3, 3},
    {on_write, PKT_UPDATE_WRITE, 9u + 1u, 9u + UPDATE_WRITE_MAX},
    {on_verify, PKT_UPDATE_VERIFY, 1, 1},
    {on_boot, PKT_UPDATE_BOOT, 1, 1},
    {on_status, PKT_UPDATE_STATUS, 1, 1},
};

bool boot_packet(struct bootloader *b, uint8_t code, const uint8_t *content, uint16_t length,
                 struct response *r)
{
    if (length == 0u || content[0] != b->id) {
        return false; /* another servo's, or broadcast */
    }
    for (size_t i = 0; i < sizeof packets / sizeof packets[0]; i++) {
        const struct boot_packet_desc *d = &packets[i];
        if (d->code == code && length >= d->min_length && length <= d->max_length) {
            const struct call c = {.b = b, .content = content, .length = length};
            r->code = code;
            r->content[0] = content[0]; /* every answer starts with the ID */
            r->length = d->handle(&c, r);
            return true;
        }
    }
    return false;
}
