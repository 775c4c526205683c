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
 * loop may be a slice of hundreds of microseconds away.
 *
 * And it skips the main loop's idle passes (tools/vboard/idle_skip.py):
 * where a pass begins (pass_at), it compares the CPU's registers and the
 * SRAM's live bytes (the static data, and the stack from SP up) with what
 * they were where the pass before began in this run, and no watched
 * register touched in between (hooks, which Python counts). The same: the
 * pass is a fixed point, and the whole passes left in the run are counted
 * as run without running them. */
#include <stdint.h>
#include <string.h>

#define THUMB_CPSIE_I 0xB662u
#define VBOARD_PASS_REGS 18

struct vboard_count {
    uint64_t executed;
    uint64_t limit;              /* stop once this many have run */
    int (*stop)(void *engine);   /* Unicorn's uc_emu_stop */
    int (*read)(void *engine, uint64_t address, void *bytes, uint64_t size); /* uc_mem_read */
    uint32_t until_cpsie;        /* set: stop before a CPSIE I ... */
    uint32_t at_cpsie;           /* ... and say so here */
    /* Skipping idle passes (set by Python: all but the last block). */
    uint32_t pass_at;            /* the pass's first instruction; 0: off for this run */
    uint32_t tries;              /* passes still to compare in this run */
    int (*reg_read)(void *engine, int id, void *value); /* uc_reg_read */
    int32_t reg_ids[VBOARD_PASS_REGS]; /* R0-R12, SP, LR, xPSR, PRIMASK, CONTROL */
    uint8_t *ram;                /* the SRAM, host memory */
    uint8_t *seen_ram;           /* a copy of its live bytes at the last pass's start */
    uint32_t ram_base, ram_size, static_end; /* static data: [0, static_end) */
    uint32_t hooks;              /* watched stores and reads: Python counts them */
    uint64_t skipped;            /* passes skipped since power-up */
    /* Kept here between two passes' starts. */
    uint32_t have_seen, seen_hooks, seen_live;
    uint32_t seen_regs[VBOARD_PASS_REGS];
    uint64_t seen_at;            /* the count at the last pass's start */
};

/* Whether the state is the one seen at the last pass's start; else it
 * becomes the one seen. */
static int same_as_last_pass(struct vboard_count *c, void *engine)
{
    uint32_t regs[VBOARD_PASS_REGS];
    for (int i = 0; i < VBOARD_PASS_REGS; i++) {
        regs[i] = 0u;
        c->reg_read(engine, c->reg_ids[i], &regs[i]);
    }
    uint32_t live = regs[13] - c->ram_base; /* SP: below it, nothing live */
    if (live < c->static_end || live > c->ram_size) {
        live = c->static_end;
    }
    if (c->have_seen && c->seen_hooks == c->hooks && c->seen_live == live &&
        memcmp(regs, c->seen_regs, sizeof regs) == 0 && memcmp(c->ram, c->seen_ram, c->static_end) == 0 &&
        memcmp(c->ram + live, c->seen_ram + live, c->ram_size - live) == 0) {
        return 1;
    }
    memcpy(c->seen_regs, regs, sizeof regs);
    memcpy(c->seen_ram, c->ram, c->static_end);
    memcpy(c->seen_ram + live, c->ram + live, c->ram_size - live);
    c->have_seen = 1u;
    c->seen_hooks = c->hooks;
    c->seen_live = live;
    return 0;
}

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
    if (c->pass_at != 0u && address == c->pass_at) {
        if (same_as_last_pass(c, engine)) {
            uint64_t length = c->executed - c->seen_at; /* a pass's instructions */
            uint64_t whole = (c->limit - c->executed) / length;
            c->executed += whole * length;
            c->skipped += whole;
            c->pass_at = 0u; /* the rest is the part-pass the run ends in */
        } else if (c->tries == 0u || --c->tries == 0u) {
            c->pass_at = 0u;
        }
        c->seen_at = c->executed;
    }
    if (c->executed++ == c->limit) {
        c->executed = c->limit; /* the hook runs before the instruction: this one does not */
        c->stop(engine);
    }
}
