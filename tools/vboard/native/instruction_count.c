/* The virtual core's instruction counter: a Unicorn code hook in C, as
 * Unicorn's own instruction count is (its emu_start count), but readable,
 * so a run that a WFI or a stalling store ends early costs the instructions
 * it ran, not its whole slice. Python registers vboard_count_instruction
 * through Unicorn's C API with a struct vboard_count as its user data. */
#include <stdint.h>

struct vboard_count {
    uint64_t executed;
    uint64_t limit;              /* stop once this many have run */
    int (*stop)(void *engine);   /* Unicorn's uc_emu_stop */
};

void vboard_count_instruction(void *engine, uint64_t address, uint32_t size, void *user);

void vboard_count_instruction(void *engine, uint64_t address, uint32_t size, void *user)
{
    (void)address;
    (void)size;
    struct vboard_count *c = user;
    if (c->executed++ == c->limit) {
        c->executed = c->limit; /* the hook runs before the instruction: this one does not */
        c->stop(engine);
    }
}
