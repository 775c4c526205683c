/* The bootloader on a simulated servo: the boards' loop (firmware/
 * bootloader/bootloader.c) on the servo's port: its receive ring and UART,
 * the config store's flash file, the slot's. */
#include "sim_servo.h"

void sim_boot_reset(struct sim_servo *s, bool stay)
{
    struct sim_boot *b = &s->boot;
    b->board = (struct boot_board){.port = &s->port, .slot = &s->slot, .board = SIM_BOARD,
                                   .stay_word = stay ? BOOT_STAY_MAGIC : 0u};
    s->rx.read = s->rx.written; /* what the application had not read is gone */
    boot_loop_start(&b->loop, &b->board);
    sim_servo_run_models(s);
    plant_coast(&s->plant); /* a reset lets go of the output */
    s->in_bootloader = true;
}

bool sim_boot_poll(struct sim_servo *s)
{
    sim_servo_run_models(s);
    if (boot_loop_step(&s->boot.loop)) {
        return true;
    }
    sim_servo_start_app(s);
    return false;
}
