#include "bootloader/boot_flow.h"

void boot_flow_start(struct boot_flow *f, bool app_valid, uint32_t stay_word)
{
    *f = (struct boot_flow){.app_valid = app_valid, .stay = stay_word == BOOT_STAY_MAGIC};
}

void boot_flow_heard(struct boot_flow *f)
{
    f->stay = true;
}

enum boot_choice boot_flow_step(const struct boot_flow *f, uint32_t elapsed_us)
{
    if (f->stay || !f->app_valid) {
        return BOOT_STAY;
    }
    return elapsed_us >= BOOT_LISTEN_MS * 1000u ? BOOT_START_APP : BOOT_WAIT;
}
