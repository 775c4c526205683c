#include "flash_double.h"

#include <string.h>

static int page_of(const struct flash_double *f, uint32_t addr, uint32_t *offset)
{
    for (int p = 0; p < 2; p++) {
        uint32_t base = f->hal.page_addr[p];
        if (addr >= base && addr < base + f->hal.page_size) {
            *offset = addr - base;
            return p;
        }
    }
    return -1;
}

/* True when this step is the one the power fails in. */
static bool cut_now(struct flash_double *f)
{
    if (f->dead) {
        return false;
    }
    bool cut = f->steps == f->cut_at;
    f->steps++;
    return cut;
}

static bool erase_page(void *ctx, uint32_t addr)
{
    struct flash_double *f = ctx;
    uint32_t offset;
    int p = page_of(f, addr, &offset);
    if (f->dead || p < 0 || offset != 0) {
        f->misuse |= p < 0 || offset != 0;
        return false;
    }
    uint8_t *page = f->mem[p];
    uint32_t size = f->hal.page_size;
    if (!cut_now(f)) {
        memset(page, 0xFF, size);
        f->erases[p]++;
        return true;
    }
    f->dead = true;
    switch (f->cut_mode) {
    case CUT_AFTER:
        memset(page, 0xFF, size);
        break;
    case CUT_PARTIAL:
        memset(page, 0xFF, size / 2);
        break;
    case CUT_SCATTER:
        for (uint32_t i = 0; i < size; i += 2) {
            page[i] = 0xFF;
        }
        break;
    default:
        break;
    }
    return false;
}

static bool program_u16(void *ctx, uint32_t addr, uint16_t value)
{
    struct flash_double *f = ctx;
    uint32_t offset;
    int p = page_of(f, addr, &offset);
    if (f->dead || p < 0 || (offset & 1u)) {
        f->misuse |= p < 0 || (offset & 1u);
        return false;
    }
    uint8_t *cell = &f->mem[p][offset];
    if (cell[0] != 0xFF || cell[1] != 0xFF) {
        f->misuse = true; /* the STM32F1 refuses to program a non-erased half-word */
        return false;
    }
    uint16_t mask = 0xFFFF; /* bits that really get cleared */
    if (cut_now(f)) {
        f->dead = true;
        static const uint16_t partial[CUT_MODES] = {0x0000, 0xFFFF, 0x00FF, 0xAAAA};
        mask = partial[f->cut_mode];
    }
    uint16_t now = (uint16_t)(cell[0] | (cell[1] << 8));
    now = (uint16_t)(now & (value | (uint16_t)~mask));
    cell[0] = (uint8_t)(now & 0xFF);
    cell[1] = (uint8_t)(now >> 8);
    return !f->dead;
}

static void read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    struct flash_double *f = ctx;
    uint32_t offset;
    int p = page_of(f, addr, &offset);
    if (p >= 0 && len <= f->hal.page_size - offset) {
        memcpy(dst, &f->mem[p][offset], len); /* the usual case, at one go */
        return;
    }
    for (uint32_t i = 0; i < len; i++) {
        p = page_of(f, addr + i, &offset);
        dst[i] = p < 0 ? 0xFF : f->mem[p][offset];
        f->misuse |= p < 0;
    }
}

void flash_double_init(struct flash_double *f, uint32_t page_size)
{
    memset(f, 0, sizeof *f);
    memset(f->mem, 0xFF, sizeof f->mem);
    f->hal = (struct hal_flash){
        .ctx = f,
        .page_size = page_size,
        .page_addr = {FLASH_DOUBLE_BASE, FLASH_DOUBLE_BASE + page_size},
        .erase_page = erase_page,
        .program_u16 = program_u16,
        .read = read,
    };
    f->cut_at = -1;
}

void flash_double_power_on(struct flash_double *f)
{
    f->dead = false;
    f->cut_at = -1;
    f->steps = 0;
}
