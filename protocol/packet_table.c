#include "protocol/packet_table.h"

#include <stddef.h>

#include "protocol/packet_codes.h"

#define ADDR PF_ADDRESSED
#define QUERY (PF_ADDRESSED | PF_ANSWERS | PF_QUERY)
#define SETTING (PF_ADDRESSED | PF_ANSWERS)
#define MOVE (PF_ADDRESSED | PF_ANSWERS_IF_CONTROL_RESPONSE | PF_BROADCAST)
/* A request's content length rule, one initialiser of struct length_rule. */
#define EXACTLY(n) {(n), (n)}
#define BETWEEN(least, most) {(least), (most)}
#define ANY_LENGTH {0, 0xFFFFu}

/* Request content lengths are those of servo-protocol.md section 3 and
 * extensions.md. WriteData carries 1 to 4 data bytes: a mismatch with the
 * item's size is answered with result 0, not treated as malformed. */
static const struct packet_desc packets[] = {
    {PKT_PING, QUERY, EXACTLY(1), handle_ping},
    {PKT_RESET_USER_DATA, SETTING, EXACTLY(1), handle_reset_user_data},
    {PKT_READ_DATA, QUERY, EXACTLY(2), handle_read_data},
    {PKT_WRITE_DATA, SETTING, BETWEEN(3, 6), handle_write_data},
    {PKT_READ_BATCH_DATA, QUERY, EXACTLY(1), handle_read_batch},
    {PKT_WRITE_BATCH_DATA, SETTING, EXACTLY(33), handle_write_batch},
    {PKT_MOVE_WHEEL, MOVE, EXACTLY(6), handle_move_wheel},
    {PKT_MOVE_ANGLE, MOVE | PF_SYNCABLE, EXACTLY(7), handle_move_angle},
    {PKT_MOVE_DAMPING, MOVE, EXACTLY(3), handle_move_damping},
    {PKT_READ_ANGLE, QUERY, EXACTLY(1), handle_read_angle},
    {PKT_MOVE_ANGLE_BY_INTERVAL, MOVE | PF_SYNCABLE, EXACTLY(11), handle_move_angle},
    {PKT_MOVE_ANGLE_BY_VELOCITY, MOVE | PF_SYNCABLE, EXACTLY(11), handle_move_angle},
    {PKT_MOVE_MULTI_TURN, MOVE | PF_SYNCABLE, EXACTLY(11), handle_move_angle},
    {PKT_MOVE_MULTI_TURN_BY_INTERVAL, MOVE | PF_SYNCABLE, EXACTLY(15), handle_move_angle},
    {PKT_MOVE_MULTI_TURN_BY_VELOCITY, MOVE | PF_SYNCABLE, EXACTLY(13), handle_move_angle},
    {PKT_READ_MULTI_TURN_ANGLE, QUERY, EXACTLY(1), handle_read_multi_turn},
    {PKT_RESET_MULTI_TURN_ANGLE, MOVE, EXACTLY(1), handle_reset_multi_turn},
    {PKT_BEGIN_ASYNC, 0, EXACTLY(0), handle_begin_async},
    {PKT_END_ASYNC, 0, EXACTLY(1), handle_end_async},
    {PKT_START_MONITOR, PF_QUERY, ANY_LENGTH, handle_ignored},
    {PKT_STOP_MONITOR, PF_QUERY, ANY_LENGTH, handle_ignored},
    {PKT_MONITOR, QUERY | PF_SYNCABLE, EXACTLY(1), handle_monitor},
    {PKT_SET_ORIGIN_POINT, ADDR | PF_BROADCAST, EXACTLY(2), handle_set_origin},
    {PKT_STOP_ON_CONTROL_MODE, ADDR | PF_BROADCAST, EXACTLY(4), handle_stop},
    {PKT_SYNC_COMMAND, 0, BETWEEN(3, 0xFFFFu), handle_sync},
};

_Static_assert(sizeof packets / sizeof packets[0] == PKT_SYNC_COMMAND,
               "one row per packet number, in order");

/* This firmware's own packets, from PKT_READ_MOTION on (docs/packets.md). */
static const struct packet_desc firmware_packets[] = {
    {PKT_READ_MOTION, QUERY, EXACTLY(1), handle_read_motion},
    {PKT_READ_STORE, QUERY, EXACTLY(1), handle_read_store},
    {PKT_ASSIGN_ID, SETTING | PF_BROADCAST | PF_ONE_ANSWERS, EXACTLY(6), handle_assign_id},
};

enum { FIRMWARE_PACKETS = sizeof firmware_packets / sizeof firmware_packets[0] };

/* The update packets (docs/packets.md). The application takes UpdateEnter
 * and UpdateStatus; the rest are the bootloader's, and an application
 * leaves them unanswered (a tool then knows to send UpdateEnter). */
static const struct packet_desc update_packets[] = {
    {PKT_UPDATE_ENTER, SETTING, EXACTLY(1), handle_update_enter},
    {PKT_UPDATE_ERASE, ADDR, ANY_LENGTH, handle_ignored},
    {PKT_UPDATE_WRITE, ADDR, ANY_LENGTH, handle_ignored},
    {PKT_UPDATE_VERIFY, ADDR, ANY_LENGTH, handle_ignored},
    {PKT_UPDATE_BOOT, ADDR, ANY_LENGTH, handle_ignored},
    {PKT_UPDATE_STATUS, QUERY, EXACTLY(1), handle_update_status},
};

enum { UPDATE_PACKETS = sizeof update_packets / sizeof update_packets[0] };

const struct packet_desc *packet_find(uint8_t code)
{
    if (code >= PKT_PING && code <= PKT_SYNC_COMMAND) {
        return &packets[code - PKT_PING];
    }
    if (code >= PKT_READ_MOTION && code < PKT_READ_MOTION + FIRMWARE_PACKETS) {
        return &firmware_packets[code - PKT_READ_MOTION];
    }
    if (code >= PKT_UPDATE_ENTER && code < PKT_UPDATE_ENTER + UPDATE_PACKETS) {
        return &update_packets[code - PKT_UPDATE_ENTER];
    }
    return NULL;
}

