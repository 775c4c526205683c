#include "bootloader.h"

#include <stddef.h>

#include "boot_flow.h"
#include "boot_packets.h"
#include "config_peek.h"
#include "protocol/data_table.h"
#include "protocol/frame_rx.h"
#include "protocol/frame_tx.h"
#include "protocol/packet_codes.h"

static struct frame_rx rx;
static uint8_t frame[RESPONSE_FRAME_MAX];

void bootloader_run(const struct boot_board *b)
{
    const struct hal_port *port = b->port;
    uint8_t id;
    uint8_t baud_index;
    config_peek_link(port->flash, &id, &baud_index);
    port->uart_set_baud(port->ctx, baud_rate_of_index(baud_index));
    static uint8_t own_id;
    own_id = id;
    frame_rx_init(&rx, &own_id);
    struct bootloader core = {.slot = b->slot, .board = b->board, .id = id};
    struct app_image_info info;
    struct boot_flow flow;
    boot_flow_start(&flow, app_image_check(b->slot, b->board, &info) == APP_IMAGE_VALID,
                    b->stay_word);
    uint32_t started_us = port->now_us(port->ctx);
    bool sending = false;
    for (;;) {
        if (b->service != NULL) {
            b->service();
        }
        uint32_t now = port->now_us(port->ctx);
        if (port->rx_sync != NULL) {
            port->rx_sync(port->rx_ctx, now);
        }
        uint32_t lost = 0;
        (void)frame_rx_take_ring(&rx, port->rx, &lost);
        if (sending) {
            if (!port->uart_tx_done(port->ctx)) {
                continue; /* half duplex */
            }
            sending = false;
            if (core.boot_now) {
                b->start_app(b->slot);
            }
        }
        const struct rx_frame *f = frame_rx_peek(&rx);
        if (f != NULL) {
            struct response r;
            uint8_t code = f->code;
            bool answered = !(f->flags & FRAME_TRUNCATED) && f->stored == f->length &&
                            boot_packet(&core, code, f->content, f->length, &r);
            frame_rx_release(&rx);
            if (answered) {
                if (code != PKT_PING) {
                    boot_flow_heard(&flow);
                }
                port->uart_send(port->ctx, frame, frame_tx_encode(&r, frame));
                sending = true;
            }
            continue;
        }
        if (boot_flow_step(&flow, (now - started_us) / 1000u) == BOOT_START_APP) {
            b->start_app(b->slot);
        }
    }
}
