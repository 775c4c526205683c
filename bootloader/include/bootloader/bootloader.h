/* The bootloader's main loop, the same on every board: it reads the
 * servo's ID and baud rate from the config store, answers Ping and the
 * update packets on the port's UART, and starts the application when the
 * boot decision says so (boot_flow.h). The board supplies the port, the
 * slot and how to start an image. */
#ifndef BOOTLOADER_BOOTLOADER_H
#define BOOTLOADER_BOOTLOADER_H

#include <stdbool.h>
#include <stdint.h>

#include "bootloader/app_image.h"
#include "bootloader/boot_flow.h"
#include "bootloader/boot_packets.h"
#include "hal/hal_port.h"
#include "protocol/frame_rx.h"
#include "protocol/frame_tx.h"

struct boot_board {
    const struct hal_port *port; /* clock, UART and its ring, the config store's flash */
    const struct app_slot *slot;
    uint16_t board;
    uint32_t stay_word;          /* what UpdateEnter left in RAM */
    /* The ID and baud index to answer at: where UpdateEnter's application
     * answered (kept_link), else the store's newest record's
     * (config_peek_link), which could be one the application refused. */
    uint8_t link_id;
    uint8_t link_baud;
    /* Starts the image in the slot (its vector table after the header);
     * does not return. */
    void (*start_app)(const struct app_slot *slot);
    /* Each pass of the loop, when the port needs it (a polled transmit);
     * NULL otherwise. */
    void (*service)(void);
};

/* The loop's state, for a board's loop or the simulator's servos. */
struct boot_loop {
    const struct boot_board *board;
    struct frame_rx rx;
    struct bootloader core;
    struct boot_flow flow;
    uint8_t id;              /* the servo's stored ID */
    uint8_t sending;         /* an answer is going out */
    uint32_t started_us;
    uint32_t idle_us;        /* a partial frame is dropped after this silence */
    struct response frame;   /* built in place, sent from here */
};

/* After reset: the stored ID and baud rate (config_peek.c) to the UART,
 * the image checked, the boot decision begun. */
void boot_loop_start(struct boot_loop *l, const struct boot_board *b);
/* One pass: true while the bootloader stays; false once the application
 * is to start (and any answer has left the wire). */
bool boot_loop_step(struct boot_loop *l);
/* The board's: boot_loop_start, passes until false, start_app. */
void bootloader_run(const struct boot_board *b);

#endif
