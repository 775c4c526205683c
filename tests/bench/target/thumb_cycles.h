/* Cycle costs of Thumb instructions, by class, from ARM's timing tables,
 * for the instruction-counting plugin's cycle model:
 *   Cortex-M3: Cortex-M3 Technical Reference Manual r2p0, table 18-1
 *     ("Cortex-M3 instruction timings");
 *   Cortex-M0: Cortex-M0 Technical Reference Manual r0p0 (ARM DDI 0432C),
 *     table 3-1 ("Cortex-M0 instruction summary"), with the single-cycle
 *     multiplier: a load or store 2, LDM/STM/PUSH/POP 1 + N, POP with the
 *     PC 4 + N (N its other registers), a taken branch, BX, BLX and MOV or
 *     ADD to the PC 3 (1 here and the refill, thumb_refill: 2), BL 4 (2 and
 *     the refill), MRS, MSR, DMB, DSB and ISB 4, the rest 1;
 *   Cortex-M0+: Cortex-M0+ Technical Reference Manual (ARM DDI 0484C),
 *     3.3, the instruction summary, with the single-cycle multiplier (the
 *     TRM's MULS "1 or 32": ST builds its M0+ parts with the fast one, its
 *     Cortex-M0+ core training: "multiply in 1 cycle"). Its 16-bit instructions
 *     cost what the M0's do (a load or store 2, LDM/STM/PUSH/POP 1 + N);
 *     its 2-stage pipeline refills in 1 cycle, not 2 (a taken branch 2,
 *     BX 2, POP with the PC 3 + N: thumb_refill), and its 32-bit ones are
 *     BL (3 in all: 2 here and the refill) and MRS, MSR, DMB, DSB, ISB (3).
 * The cost here is the instruction's own, a branch's as not taken; a taken
 * branch's pipeline refill and the flash's wait states are added by the
 * plugin where they happen (qemu_insn_count.c). Where a table gives a range
 * the middle is used (a multiply-long 3-5: 4; a divide 2-12: 7), and an
 * IT instruction, which the M3 folds into its neighbour (0-1), counts 1.
 * The M3 pipelines neighbouring single loads and stores (TRM 18.3, "Load-
 * store timings": LDR after LDR/STR takes 1 cycle, its address phase
 * overlapping the previous data phase); the plugin takes that cycle off
 * where two follow each other. The M0's table gives a load 2 cycles flat. */
#ifndef THUMB_CYCLES_H
#define THUMB_CYCLES_H

#include <stdbool.h>
#include <stdint.h>

enum core { CORE_M3, CORE_M0, CORE_M0P };

struct insn_cost {
    uint8_t cycles;        /* the instruction's own, not taken */
    bool literal_load;     /* LDR from a PC-relative literal: a flash read */
    bool writes_pc;        /* a branch, or a POP / LDM / LDR of the PC */
    bool single_ldst;      /* one LDR/STR (any size): pipelines with the next on the M3 */
};

/* hw: the instruction's first half-word; hw2 its second (32-bit ones). */
struct insn_cost thumb_cost(enum core core, uint16_t hw, uint16_t hw2, unsigned size);

/* The cycles a taken branch adds for the pipeline's refill, before the
 * flash's wait states: the M3's P (1-3, TRM 18.2: 2, the middle) and the
 * M0's (a taken branch 3 = 1 + 2) are 2, the M0+'s 1 (a taken branch 2). */
unsigned thumb_refill(enum core core);

#endif
