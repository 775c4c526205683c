#include "bootloader/bootloader.h"

#include <stddef.h>

#include "registers/data_table.h"
#include "protocol/packet_codes.h"

void boot_loop_start(struct boot_loop *l, const struct boot_board *b)
{
    const struct hal_port *port = b->port;
    l->id = b->link_id;
    uint32_t baud = baud_rate_of_index(b->link_baud);
    port->bus.set_baud(port->ctx, baud);
    l->idle_us = frame_rx_port_idle_us(frame_rx_idle_us(baud), port->rx_gap_tolerance_us);
    l->board = b;
    l->sending = 0;
    frame_rx_init(&l->rx, &l->id);
    l->core = (struct bootloader){.slot = b->slot, .board = b->board, .id = l->id};
    struct app_image_info info;
    boot_flow_start(&l->flow, bootloader_check(&l->core, &info) == APP_IMAGE_VALID, b->stay_word);
    l->started_us = port->bus.now_us(port->ctx);
}

bool boot_loop_step(struct boot_loop *l)
{
    const struct hal_port *port = l->board->port;
    uint32_t now = port->bus.now_us(port->ctx);
    hal_rx_sync(port, now);
    uint32_t lost = 0;
    frame_rx_receive(&l->rx, port->rx, &lost, now, l->idle_us);
    if (l->sending) {
        if (!port->bus.tx_done(port->ctx)) {
            return true; /* half duplex */
        }
        l->sending = 0;
        if (l->core.boot_now) {
            return false; /* UpdateBoot's answer has left */
        }
    }
    const struct rx_frame *f = frame_rx_peek(&l->rx);
    if (f != NULL) {
        uint8_t code = f->code;
        bool answered = !(f->flags & FRAME_TRUNCATED) && f->stored == f->length &&
                        boot_packet(&l->core, code, f->content, f->length, &l->frame);
        frame_rx_release(&l->rx);
        if (answered) {
            if (code != PKT_PING) {
                boot_flow_heard(&l->flow);
            }
            uint8_t size = frame_tx_seal(&l->frame);
            port->bus.send(port->ctx, frame_tx_bytes(&l->frame), size);
            l->sending = 1;
        }
        return true;
    }
    return boot_flow_step(&l->flow, now - l->started_us) != BOOT_START_APP;
}

void bootloader_run(const struct boot_board *b)
{
    static struct boot_loop loop;
    boot_loop_start(&loop, b);
    do {
        if (b->service != NULL) {
            b->service();
        }
    } while (boot_loop_step(&loop));
    b->start_app(b->slot);
}
