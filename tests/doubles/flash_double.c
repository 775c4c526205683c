#include "doubles/flash_double.h"

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
        if (f->during_erase != NULL) {
            f->during_erase(f->during_erase_ctx);
        }
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

/* One program step of write_block bytes; a cut leaves some of its bits. */
static bool program(void *ctx, uint32_t addr, const uint8_t *data)
{
    struct flash_double *f = ctx;
    uint32_t block = f->hal.write_block;
    uint32_t offset;
    int p = page_of(f, addr, &offset);
    if (f->dead || p < 0 || offset % block != 0u || offset + block > f->hal.page_size) {
        f->misuse |= p < 0 || offset % block != 0u;
        return false;
    }
    uint8_t *cell = &f->mem[p][offset];
    for (uint32_t i = 0; i < block; i++) {
        if (cell[i] != 0xFF) {
            f->misuse = true; /* flash refuses to program a non-erased block */
            return false;
        }
    }
    uint8_t mask = 0xFF; /* bits that really get cleared */
    if (cut_now(f)) {
        f->dead = true;
        static const uint8_t partial[CUT_MODES] = {0x00, 0xFF, 0xFF, 0xAA};
        mask = partial[f->cut_mode];
    }
    for (uint32_t i = 0; i < block; i++) {
        /* A partial cut lands the block's first half; a scattered one every
         * other bit. */
        uint8_t m = (f->dead && f->cut_mode == CUT_PARTIAL && i >= block / 2u) ? 0x00 : mask;
        cell[i] = (uint8_t)(cell[i] & (data[i] | (uint8_t)~m));
    }
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
    f->hal = hal_flash_two_pages(f, page_size, FLASH_DOUBLE_BASE, erase_page, program, read);
    f->cut_at = -1;
}

void flash_double_power_on(struct flash_double *f)
{
    f->dead = false;
    f->cut_at = -1;
    f->steps = 0;
}
