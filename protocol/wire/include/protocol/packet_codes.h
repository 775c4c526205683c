/* Packet numbers of servo-protocol.md (1-17) and extensions.md (18-25), and
 * this firmware's own from 0x40 (docs/packets.md), a range the maker's
 * protocol does not use. */
#ifndef PROTOCOL_PACKET_CODES_H
#define PROTOCOL_PACKET_CODES_H

#include <stdbool.h>
#include <stdint.h>

enum packet_code {
    PKT_PING = 1,
    PKT_RESET_USER_DATA = 2,
    PKT_READ_DATA = 3,
    PKT_WRITE_DATA = 4,
    PKT_READ_BATCH_DATA = 5,
    PKT_WRITE_BATCH_DATA = 6,
    PKT_MOVE_WHEEL = 7,
    PKT_MOVE_ANGLE = 8,
    PKT_MOVE_DAMPING = 9,
    PKT_READ_ANGLE = 10,
    PKT_MOVE_ANGLE_BY_INTERVAL = 11,
    PKT_MOVE_ANGLE_BY_VELOCITY = 12,
    PKT_MOVE_MULTI_TURN = 13,
    PKT_MOVE_MULTI_TURN_BY_INTERVAL = 14,
    PKT_MOVE_MULTI_TURN_BY_VELOCITY = 15,
    PKT_READ_MULTI_TURN_ANGLE = 16,
    PKT_RESET_MULTI_TURN_ANGLE = 17,
    PKT_BEGIN_ASYNC = 18,
    PKT_END_ASYNC = 19,
    PKT_START_MONITOR = 20, /* no published format: ignored */
    PKT_STOP_MONITOR = 21,  /* no published format: ignored */
    PKT_MONITOR = 22,
    PKT_SET_ORIGIN_POINT = 23,
    PKT_STOP_ON_CONTROL_MODE = 24,
    PKT_SYNC_COMMAND = 25,
};

enum firmware_packet_code {
    PKT_READ_MOTION = 0x40, /* a snapshot of the motion state, for tuning */
    PKT_READ_STORE = 0x41,  /* the config store's health and wear */
    PKT_ASSIGN_ID = 0x42,   /* a new ID for the servo with a serial number */
    /* Firmware update over the bus (docs/packets.md, firmware/bootloader/). */
    PKT_UPDATE_ENTER = 0x50,  /* the application restarts into the bootloader */
    PKT_UPDATE_ERASE = 0x51,  /* erase one page of the application slot */
    PKT_UPDATE_WRITE = 0x52,  /* program bytes at an offset, with their CRC */
    PKT_UPDATE_VERIFY = 0x53, /* check the image in the slot */
    PKT_UPDATE_BOOT = 0x54,   /* start the image, if it checks */
    PKT_UPDATE_STATUS = 0x55, /* who answers: application or bootloader, versions */
};

/* Packets 0-31 whose content does not start with the servo ID: the rows of
 * packet_table.c without PF_ADDRESSED (test_dispatcher checks every code
 * against packet_find). */
#define PACKETS_UNADDRESSED_BELOW_32                                                       \
    ((1u << PKT_BEGIN_ASYNC) | (1u << PKT_END_ASYNC) | (1u << PKT_START_MONITOR) |        \
     (1u << PKT_STOP_MONITOR) | (1u << PKT_SYNC_COMMAND))

/* The packet's content starts with the servo ID: PF_ADDRESSED, or unknown
 * (judged by the ID position every addressed packet uses). The framer asks
 * for every request on the bus. */
static inline bool packet_is_addressed(uint8_t code)
{
    return code >= 32u || !((PACKETS_UNADDRESSED_BELOW_32 >> code) & 1u);
}

#endif
