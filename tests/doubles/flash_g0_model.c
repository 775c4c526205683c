#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, MAP_32BIT */
#include "doubles/flash_g0_model.h"

#include <string.h>
#include <sys/mman.h>

#include "ports/stm32g0/flash_g0.h"
#include "ports/stm32g0/stm32g0_regs.h"

static struct g0_flash_model *model;

/* The access g0_model_reg last handed out: the driver has done it by the
 * time it makes the next one, which is when the model acts on a write. */
enum kind { NONE, SR, CR, CELL, LATCH };
static enum kind last_kind;
static volatile uint32_t *last;
static uint32_t last_value;
static volatile uint32_t scratch; /* registers the model does not keep */

bool g0_model_init(struct g0_flash_model *m)
{
    const size_t size = G0_MODEL_PAGE * G0_MODEL_PAGES;
    static uint8_t *mapped;
    if (mapped == NULL) {
        int flags = MAP_PRIVATE | MAP_ANONYMOUS;
#ifdef MAP_32BIT
        flags |= MAP_32BIT;
#endif
        void *p = mmap((void *)(uintptr_t)0x10000000u, size, PROT_READ | PROT_WRITE, flags, -1, 0);
        if (p == MAP_FAILED) {
            return false;
        }
        mapped = p;
    }
    uintptr_t at = (uintptr_t)mapped;
    if (at > UINT32_MAX - size || (at < G0_FLASH_BASE_REG + 0x400u && at + size > G0_FLASH_BASE_REG)) {
        return false;
    }
    memset(m, 0, sizeof *m);
    m->mem = mapped;
    m->base = (uint32_t)at;
    memset(m->mem, 0xFF, size);
    m->cut_at = -1;
    m->cr = G0_FLASH_CR_LOCK;
    model = m;
    last_kind = NONE;
    return true;
}

void g0_model_power_on(struct g0_flash_model *m)
{
    m->dead = false;
    m->cut_at = -1;
    m->steps = 0;
    m->latched = 0;
    m->sr = 0;
    m->cr = G0_FLASH_CR_LOCK;
    last_kind = NONE;
}

uint32_t g0_model_addr(const struct g0_flash_model *m, uint32_t page, uint32_t offset)
{
    return m->base + page * G0_MODEL_PAGE + offset;
}

/* True when this step is the one the power fails in. */
static bool cut_now(struct g0_flash_model *m)
{
    bool cut = m->steps == m->cut_at;
    m->steps++;
    return cut;
}

static void put_word(struct g0_flash_model *m, uint32_t off, uint32_t w)
{
    for (unsigned i = 0; i < 4u; i++) {
        m->mem[off + i] &= (uint8_t)(w >> (8u * i)); /* programming clears bits only */
    }
}

/* The double word in the latch, as PG and the second word's write start it. */
static void program_unit(struct g0_flash_model *m)
{
    uint32_t off = m->latch_addr - m->base;
    if ((off & 7u) != 0u) {
        m->sr |= G0_FLASH_SR_PGAERR;
        m->misuse = true;
        return;
    }
    uint32_t unit = off / 8u;
    bool erased = !m->torn[unit];
    for (unsigned i = 0; i < 8u; i++) {
        erased = erased && m->mem[off + i] == 0xFFu;
    }
    if (m->dead || !erased) {
        m->sr |= G0_FLASH_SR_PROGERR; /* RM0444 3.7.5: a double word not erased */
        return;
    }
    m->programs++;
    put_word(m, off, m->latch[0]);
    if (!cut_now(m)) {
        put_word(m, off + 4u, m->latch[1]);
        return;
    }
    m->dead = true;
    if (m->tear == G0_TEAR_ECC) {
        put_word(m, off + 4u, m->latch[1]);
    }
    m->torn[unit] = true;
    m->sr |= G0_FLASH_SR_PROGERR;
}

static void erase(struct g0_flash_model *m)
{
    uint32_t page = (m->cr & G0_FLASH_CR_PNB_MASK) >> G0_FLASH_CR_PNB_SHIFT;
    if (page >= G0_MODEL_PAGES) {
        m->misuse = true;
        return;
    }
    if (m->dead) {
        m->sr |= G0_FLASH_SR_PGSERR;
        return;
    }
    /* A cut erase leaves the page's first half erased. */
    bool cut = cut_now(m);
    uint32_t n = cut ? G0_MODEL_PAGE / 2u : G0_MODEL_PAGE;
    memset(&m->mem[page * G0_MODEL_PAGE], 0xFF, n);
    memset(&m->torn[page * G0_MODEL_PAGE / 8u], 0, n / 8u * sizeof m->torn[0]);
    m->erases[page]++;
    if (cut) {
        m->dead = true;
        m->sr |= G0_FLASH_SR_PGSERR;
    }
}

/* What the access handed out last did, now that it is done. */
static void commit(struct g0_flash_model *m)
{
    enum kind k = last_kind;
    last_kind = NONE;
    switch (k) {
    case SR:
        if (m->sr != last_value) { /* written: its ones clear flags */
            m->sr = last_value & ~m->sr;
        }
        break;
    case CR:
        if ((m->cr & (G0_FLASH_CR_PER | G0_FLASH_CR_STRT)) == (G0_FLASH_CR_PER | G0_FLASH_CR_STRT)) {
            m->cr &= ~G0_FLASH_CR_STRT;
            erase(m);
        }
        break;
    case CELL:
        m->misuse |= *last != last_value; /* a store to flash without PG */
        break;
    case LATCH:
        if (++m->latched == 2u) {
            m->latched = 0;
            program_unit(m);
        }
        break;
    default:
        break;
    }
}

static volatile uint32_t *hand_out(enum kind k, volatile uint32_t *p)
{
    last_kind = k;
    last = p;
    last_value = *p;
    return p;
}

volatile uint32_t *g0_model_reg(uint32_t addr)
{
    struct g0_flash_model *m = model;
    commit(m);
    uint32_t off = addr - m->base;
    if (addr >= m->base && off < G0_MODEL_PAGE * G0_MODEL_PAGES) {
        m->misuse |= (off & 3u) != 0u;
        if (m->cr & G0_FLASH_CR_PG) { /* a program step's word */
            if (m->latched == 0u) {
                m->latch_addr = addr;
            } else if (addr != m->latch_addr + 4u) {
                m->misuse = true; /* not the double word's second word */
            }
            return hand_out(LATCH, &m->latch[m->latched]);
        }
        if (m->torn[off / 8u]) {
            /* The ECC double error: its flag and the NMI (RM0444 3.3.9),
             * whose handler must take it as the flash's. */
            m->eccr = G0_FLASH_ECCR_ECCD | (off / 8u);
            m->nmis++;
            m->misuse |= !flash_g0_nmi_ecc();
            commit(m);
            m->eccr = 0;
        }
        return hand_out(CELL, (volatile uint32_t *)(uintptr_t)addr);
    }
    switch (addr) {
    case G0_FLASH_BASE_REG + 0x10u:
        return hand_out(SR, &m->sr);
    case G0_FLASH_BASE_REG + 0x14u:
        return hand_out(CR, &m->cr);
    case G0_FLASH_BASE_REG + 0x18u:
        return hand_out(NONE, &m->eccr);
    case G0_FLASH_BASE_REG + 0x08u: /* KEYR: the model does not lock */
        return hand_out(NONE, &scratch);
    default:
        m->misuse = true;
        return hand_out(NONE, &scratch);
    }
}
