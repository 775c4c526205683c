#include "protocol/packet_table.h"

#include <stddef.h>

#include "protocol/packet_codes.h"
#include "protocol/packet_rows.h"

/* Three tables, each a run of consecutive codes, their rows made from
 * protocol/servo_schema: the maker's and its clients' packets (1-25), this
 * firmware's own from 0x40, and the update packets from 0x50. The update
 * packets other than UpdateEnter and UpdateStatus are the bootloader's: an
 * application leaves them unanswered (a tool then knows to send
 * UpdateEnter). WriteData's 1 to 4 data bytes: a mismatch with the item's
 * size is answered with result 0, not treated as malformed. */
static const struct packet_desc packets[] = {PACKET_TABLE_NUMBERED_ROWS};
static const struct packet_desc firmware_packets[] = {PACKET_TABLE_FIRMWARE_ROWS};
static const struct packet_desc update_packets[] = {PACKET_TABLE_UPDATE_ROWS};

_Static_assert(sizeof packets / sizeof packets[0] == PACKET_TABLE_NUMBERED_COUNT &&
                   PACKET_TABLE_NUMBERED_FIRST == PKT_PING,
               "the numbered packets from 1");
_Static_assert(sizeof firmware_packets / sizeof firmware_packets[0] == PACKET_TABLE_FIRMWARE_COUNT,
               "one row per firmware packet");
_Static_assert(sizeof update_packets / sizeof update_packets[0] == PACKET_TABLE_UPDATE_COUNT,
               "one row per update packet");

const struct packet_desc *packet_find(uint8_t code)
{
    if (code >= PACKET_TABLE_NUMBERED_FIRST &&
        code < PACKET_TABLE_NUMBERED_FIRST + PACKET_TABLE_NUMBERED_COUNT) {
        return &packets[code - PACKET_TABLE_NUMBERED_FIRST];
    }
    if (code >= PACKET_TABLE_FIRMWARE_FIRST &&
        code < PACKET_TABLE_FIRMWARE_FIRST + PACKET_TABLE_FIRMWARE_COUNT) {
        return &firmware_packets[code - PACKET_TABLE_FIRMWARE_FIRST];
    }
    if (code >= PACKET_TABLE_UPDATE_FIRST &&
        code < PACKET_TABLE_UPDATE_FIRST + PACKET_TABLE_UPDATE_COUNT) {
        return &update_packets[code - PACKET_TABLE_UPDATE_FIRST];
    }
    return NULL;
}

