#include "bench/target/thumb_cycles.h"

static unsigned bits_set(uint32_t v)
{
    unsigned n = 0;
    for (; v != 0u; v &= v - 1u) {
        n++;
    }
    return n;
}

static struct insn_cost cost(uint8_t cycles, bool literal, bool pc)
{
    return (struct insn_cost){cycles, literal, pc, false};
}

static struct insn_cost ldst(uint8_t cycles, bool literal, bool pc)
{
    return (struct insn_cost){cycles, literal, pc, true};
}

static struct insn_cost thumb16(enum core core, uint16_t hw)
{
    uint8_t load = 2;                       /* M3, M0 and M0+ alike */
    uint8_t store = core == CORE_M3 ? 1 : 2; /* the M3 buffers a store; the M0 and M0+: 2 */
    if ((hw >> 11) == 0x09) {               /* LDR Rt, [PC, #imm] */
        return ldst(load, true, false);
    }
    if ((hw >> 12) == 0x5) {                /* load/store, register offset */
        return ldst(((hw >> 9) & 7u) <= 2u ? store : load, false, false);
    }
    if ((hw >> 13) == 0x3 || (hw >> 12) == 0x8 || (hw >> 12) == 0x9) { /* imm, halfword, SP */
        return ldst((hw & 0x0800u) ? load : store, false, false);
    }
    if ((hw & 0xFE00u) == 0xB400u) {        /* PUSH */
        return cost((uint8_t)(1u + bits_set(hw & 0x1FFu)), false, false);
    }
    if ((hw & 0xFE00u) == 0xBC00u) {        /* POP, maybe of the PC */
        return cost((uint8_t)(1u + bits_set(hw & 0x1FFu)), false, (hw & 0x100u) != 0u);
    }
    if ((hw >> 12) == 0xC) {                /* LDM / STM */
        return cost((uint8_t)(1u + bits_set(hw & 0xFFu)), false, false);
    }
    if ((hw & 0xF500u) == 0xB100u || (hw >> 12) == 0xD || (hw >> 11) == 0x1C) {
        return cost(1, false, true);        /* CBZ/CBNZ, B<cond>, B */
    }
    if ((hw & 0xFF00u) == 0x4700u) {        /* BX / BLX register */
        return cost(1, false, true);
    }
    if ((hw & 0xFF87u) == 0x4687u) {        /* MOV PC, Rm */
        return cost(1, false, true);
    }
    return cost(1, false, false);           /* data processing, MULS, IT, hints */
}

static struct insn_cost thumb32(uint16_t hw, uint16_t hw2)
{
    if ((hw & 0xFFD0u) == 0xE880u || (hw & 0xFFD0u) == 0xE900u) { /* STM (IA, DB) */
        return cost((uint8_t)(1u + bits_set(hw2)), false, false);
    }
    if ((hw & 0xFFD0u) == 0xE890u || (hw & 0xFFD0u) == 0xE910u) { /* LDM (IA, DB), maybe of the PC */
        return cost((uint8_t)(1u + bits_set(hw2)), false, (hw2 & 0x8000u) != 0u);
    }
    if ((hw & 0xFE40u) == 0xE840u) {       /* LDRD / STRD, exclusives, table branch */
        if ((hw & 0xFFF0u) == 0xE8D0u && (hw2 & 0xFFE0u) == 0xF000u) {
            return cost(3, false, true);    /* TBB / TBH */
        }
        return cost(3, false, false);
    }
    if ((hw & 0xFE00u) == 0xF800u) {       /* loads and stores */
        bool load = (hw & 0x0010u) != 0u;
        bool literal = load && (hw & 0x000Fu) == 0xFu;
        bool to_pc = load && (hw2 >> 12) == 0xFu;
        return ldst(load ? 2 : 1, literal, to_pc);
    }
    if ((hw & 0xFF80u) == 0xFB00u) {       /* MUL, MLA, MLS */
        return cost((hw2 & 0x00F0u) == 0u && (hw2 >> 12) == 0xFu ? 1 : 2, false, false);
    }
    if ((hw & 0xFF80u) == 0xFB80u) {       /* long multiply, divide */
        unsigned op = (hw >> 4) & 7u;
        return cost(op == 1u || op == 3u ? 7 : 4, false, false);
    }
    if ((hw & 0xF800u) == 0xF000u && (hw2 & 0x8000u) != 0u) {
        return cost(1, false, true);        /* B, B<cond>, BL */
    }
    return cost(1, false, false);
}

/* ARMv6-M's 32-bit instructions: BL, or MRS, MSR and the barriers. BL is
 * 4 cycles on the M0 (TRM table 3-1) and 3 on the M0+ (TRM 3.3): 2 here
 * and the refill the plugin adds after it (thumb_refill: 2, 1). MRS, MSR,
 * DMB, DSB and ISB are 4 on the M0 and 3 on the M0+. */
static struct insn_cost v6m_thumb32(enum core core, uint16_t hw, uint16_t hw2)
{
    if ((hw & 0xF800u) == 0xF000u && (hw2 & 0xD000u) == 0xD000u) {
        return cost(2, false, true);        /* BL */
    }
    return cost(core == CORE_M0P ? 3 : 4, false, false); /* MRS, MSR, DMB, DSB, ISB */
}

struct insn_cost thumb_cost(enum core core, uint16_t hw, uint16_t hw2, unsigned size)
{
    if (size == 4u) {
        return core == CORE_M3 ? thumb32(hw, hw2) : v6m_thumb32(core, hw, hw2);
    }
    return thumb16(core, hw);
}

unsigned thumb_refill(enum core core)
{
    return core == CORE_M0P ? 1u : 2u;
}
