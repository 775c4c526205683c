#include "boot_flow.h"

void boot_flow_start(struct boot_flow *f, bool app_valid, uint32_t stay_word)
{
    *f = (struct boot_flow){.app_valid = app_valid, .stay = stay_word == BOOT_STAY_MAGIC};
}

void boot_flow_heard(struct boot_flow *f)
{
    f->stay = true;
}

enum boot_choice boot_flow_step(struct boot_flow *f, uint32_t elapsed_ms)
{
    f->since_ms = elapsed_ms;
    if (f->stay || !f->app_valid) {
        return BOOT_STAY;
    }
    return elapsed_ms >= BOOT_LISTEN_MS ? BOOT_START_APP : BOOT_WAIT;
}
