/* All of a save at once, whatever the stall: where no control loop runs
 * yet or any more (the servo's boot, its restart into the bootloader),
 * the simulator's factory ID, and tests. The running servo saves in steps
 * (servo.c). */
#include "storage/config_store.h"

enum config_save_result config_store_save(struct config_store *s, const struct user_config *cfg,
                                          uint32_t op_seconds)
{
    enum config_save_result r = config_store_begin(s, cfg, op_seconds);
    if (r == CONFIG_NEEDS_ERASE) {
        if (!config_store_erase_spare(s)) {
            return CONFIG_WRITE_FAILED;
        }
        r = config_store_begin(s, cfg, op_seconds);
    }
    while (r == CONFIG_STARTED || r == CONFIG_BUSY) {
        r = config_store_step(s);
    }
    return r;
}
