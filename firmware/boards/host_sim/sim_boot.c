/* The bootloader on a simulated servo: its decisions and answers are the
 * bootloader core's (firmware/bootloader/), on the servo's port: the same
 * receive ring, its stored ID and baud rate, the slot's flash file. */
#include <stddef.h>

#include "sim_bus.h"
#include "sim_servo.h"

#include "config_store.h"
#include "protocol/data_table.h"
#include "protocol/packet_codes.h"

void sim_boot_reset(struct sim_servo *s, bool stay)
{
    struct config_store store;
    struct user_config cfg;
    config_store_load(&store, &s->flash.hal, &cfg);
    struct sim_boot *b = &s->boot;
    b->id = cfg.servo_id;
    s->baud = baud_rate_of_index(cfg.baud_index);
    frame_rx_init(&b->rx, &b->id);
    b->core = (struct bootloader){.slot = &s->slot, .board = SIM_BOARD, .id = cfg.servo_id};
    struct app_image_info info;
    bool valid = app_image_check(&s->slot, SIM_BOARD, &info) == APP_IMAGE_VALID;
    boot_flow_start(&b->flow, valid, stay ? BOOT_STAY_MAGIC : 0u);
    b->since_us = s->bus->now_us;
    s->rx.read = s->rx.written; /* what the application had not read is gone */
    sim_servo_run_models(s);
    plant_coast(&s->plant); /* a reset lets go of the output */
    s->in_bootloader = true;
}

bool sim_boot_poll(struct sim_servo *s, uint64_t now_us)
{
    struct sim_boot *b = &s->boot;
    sim_servo_run_models(s);
    if (now_us < s->tx_done_us) {
        return true; /* half duplex: the answer is still going out */
    }
    if (b->core.boot_now) {
        sim_servo_start_app(s);
        return false;
    }
    uint32_t lost = 0;
    (void)frame_rx_take_ring(&b->rx, &s->rx, &lost);
    const struct rx_frame *f = frame_rx_peek(&b->rx);
    if (f != NULL) {
        struct response r;
        uint8_t code = f->code;
        bool answered = !(f->flags & FRAME_TRUNCATED) && f->stored == f->length &&
                        boot_packet(&b->core, code, f->content, f->length, &r);
        frame_rx_release(&b->rx);
        if (answered) {
            if (code != PKT_PING) {
                boot_flow_heard(&b->flow);
            }
            uint8_t n = frame_tx_encode(&r, b->frame);
            s->tx_done_us = sim_bus_send(s->bus, s->index, b->frame, n, s->baud, now_us);
        }
        return true;
    }
    if (boot_flow_step(&b->flow, (uint32_t)((now_us - b->since_us) / 1000u)) == BOOT_START_APP) {
        sim_servo_start_app(s);
        return false;
    }
    return true;
}
