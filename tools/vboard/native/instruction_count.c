/* The virtual core's instruction counter: a Unicorn code hook in C, as
 * Unicorn's own instruction count is (its emu_start count), but readable,
 * so a run that a WFI or a stalling store ends early costs the instructions
 * it ran, not its whole slice. Python registers vboard_count_instruction
 * through Unicorn's C API with a struct vboard_count as its user data.
 *
 * A run that starts with PRIMASK set and an exception pending also ends
 * before the CPSIE I that unmasks it (until_cpsie): on silicon the
 * exception is taken right after that instruction (ARMv6-M ARM B1.4.3,
 * ARMv7-M ARM B1.4.3), not at the end of the run, which on a busy main
 * loop may be a slice of hundreds of microseconds away. */
#include <stdint.h>

#define THUMB_CPSIE_I 0xB662u

struct vboard_count {
    uint64_t executed;
    uint64_t limit;              /* stop once this many have run */
    int (*stop)(void *engine);   /* Unicorn's uc_emu_stop */
    int (*read)(void *engine, uint64_t address, void *bytes, uint64_t size); /* uc_mem_read */
    uint32_t until_cpsie;        /* set: stop before a CPSIE I ... */
    uint32_t at_cpsie;           /* ... and say so here */
};

void vboard_count_instruction(void *engine, uint64_t address, uint32_t size, void *user);

void vboard_count_instruction(void *engine, uint64_t address, uint32_t size, void *user)
{
    struct vboard_count *c = user;
    if (c->until_cpsie && size == 2u) { /* few instructions: the masked stretch only */
        uint16_t op = 0;
        if (c->read(engine, address, &op, 2u) == 0 && op == THUMB_CPSIE_I) {
            c->at_cpsie = 1u;
            c->stop(engine); /* before it, as below: Python carries it out */
            return;
        }
    }
    if (c->executed++ == c->limit) {
        c->executed = c->limit; /* the hook runs before the instruction: this one does not */
        c->stop(engine);
    }
}
