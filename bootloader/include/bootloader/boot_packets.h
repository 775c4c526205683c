/* What the bootloader answers on the bus, at the servo's stored ID and
 * baud rate: the maker's Ping, so tools find a servo waiting for an image,
 * and the update packets (docs/packets.md, 0x50-0x55). One table row per
 * packet: code, content length, handler. Broadcast is never taken: an
 * update is for one servo on a shared bus. */
#ifndef BOOTLOADER_BOOT_PACKETS_H
#define BOOTLOADER_BOOT_PACKETS_H

#include <stdbool.h>
#include <stdint.h>

#include "bootloader/app_image.h"
#include "protocol/frame_tx.h"
#include "hal/must_check.h"

#define BOOTLOADER_VERSION 3u /* 2: a repeated UpdateWrite succeeds; 3: reason 5 */
/* Largest data in one UpdateWrite: the request (9 + 24 bytes) fits the
 * framer every build shares (FRAME_CONTENT_MAX, 34), so the bootloader
 * needs no framer of its own. */
#define UPDATE_WRITE_MAX 24u

struct bootloader {
    const struct app_slot *slot;
    uint16_t board;        /* images for another board are refused */
    uint8_t id;            /* the servo's stored ID */
    uint8_t boot_now;      /* UpdateBoot taken: start the image once the answer is out */
    uint8_t checked;       /* the two below hold: no erase or write since the check */
    uint8_t verdict;       /* enum app_image_verdict, the slot's last check */
    uint16_t version;      /* its image's version (app_image_info) */
};

/* The slot checked (app_image_check) and the verdict kept for UpdateStatus,
 * which answers from it until an erase or a write: on an M0 the bitwise
 * CRC of a 28 KB image takes 66 ms, longer than a host waits for that
 * answer while it polls for the bootloader. */
enum app_image_verdict bootloader_check(struct bootloader *b, struct app_image_info *info);

/* A request's packet code and content; true with r filled when it is
 * answered. An answered update packet (not a Ping) keeps the bootloader
 * from starting the application (boot_flow_heard). */
MUST_CHECK bool boot_packet(struct bootloader *b, uint8_t code, const uint8_t *content, uint16_t length,
                 struct response *r);

#endif
