/* The bootloader's main loop, the same on every board: it reads the
 * servo's ID and baud rate from the config store, answers Ping and the
 * update packets on the port's UART, and starts the application when the
 * boot decision says so (boot_flow.h). The board supplies the port, the
 * slot and how to start an image. */
#ifndef BOOTLOADER_BOOTLOADER_H
#define BOOTLOADER_BOOTLOADER_H

#include <stdint.h>

#include "app_image.h"
#include "hal/hal_port.h"

struct boot_board {
    const struct hal_port *port; /* clock, UART and its ring, the config store's flash */
    const struct app_slot *slot;
    uint16_t board;
    uint32_t stay_word;          /* what UpdateEnter left in RAM */
    /* Starts the image in the slot (its vector table after the header);
     * does not return. */
    void (*start_app)(const struct app_slot *slot);
    /* Each pass of the loop, when the port needs it (a polled transmit);
     * NULL otherwise. */
    void (*service)(void);
};

void bootloader_run(const struct boot_board *b);

#endif
