/* What the bootloader does after reset: start the application, or stay
 * and wait for an image.
 *
 * It stays when the application asked for it (UpdateEnter leaves a word in
 * RAM that survives the reset), when the slot holds no valid image (an
 * update cut short, a blank part), and when an update packet for this
 * servo arrives in the first BOOT_LISTEN_MS after reset (so a servo whose
 * application hangs the bus can still be reached: power it up and send
 * UpdateStatus at once; a Ping does not keep it). Otherwise it starts the
 * application once that window has passed. */
#ifndef BOOTLOADER_BOOT_FLOW_H
#define BOOTLOADER_BOOT_FLOW_H

#include <stdbool.h>
#include <stdint.h>

#define BOOT_LISTEN_MS 200u
/* The word UpdateEnter leaves in RAM for the bootloader. */
#define BOOT_STAY_MAGIC 0xB007B007u

enum boot_choice {
    BOOT_WAIT,      /* still listening */
    BOOT_START_APP,
    BOOT_STAY,      /* for good: until UpdateBoot */
};

struct boot_flow {
    bool app_valid;     /* app_image_check said so at reset */
    bool stay;          /* asked to, or a request came in the window */
};

void boot_flow_start(struct boot_flow *f, bool app_valid, uint32_t stay_word);
/* An update packet for this servo was answered. */
void boot_flow_heard(struct boot_flow *f);
/* elapsed_us: since reset (microseconds, so the caller needs no division;
 * once the window has passed, no later time is asked about). */
enum boot_choice boot_flow_step(const struct boot_flow *f, uint32_t elapsed_us);

#endif
