#include "sim_flash.h"

#include <stdio.h>
#include <string.h>

#define BASE 0x0800F800u

static bool save(const struct sim_flash *f)
{
    char tmp[300];
    snprintf(tmp, sizeof tmp, "%s.tmp", f->path);
    FILE *out = fopen(tmp, "wb");
    if (out == NULL) {
        return false;
    }
    bool ok = fwrite(f->mem, 1, sizeof f->mem, out) == sizeof f->mem;
    ok = (fclose(out) == 0) && ok;
    return ok && rename(tmp, f->path) == 0;
}

static bool erase_page(void *ctx, uint32_t addr)
{
    struct sim_flash *f = ctx;
    if (addr != BASE && addr != BASE + SIM_FLASH_PAGE) {
        return false;
    }
    memset(&f->mem[addr - BASE], 0xFF, SIM_FLASH_PAGE);
    return save(f);
}

static bool program_u16(void *ctx, uint32_t addr, uint16_t value)
{
    struct sim_flash *f = ctx;
    if (addr < BASE || addr + 2u > BASE + sizeof f->mem || (addr & 1u)) {
        return false;
    }
    uint8_t *cell = &f->mem[addr - BASE];
    if (cell[0] != 0xFF || cell[1] != 0xFF) {
        return false;
    }
    cell[0] = (uint8_t)(value & 0xFFu);
    cell[1] = (uint8_t)(value >> 8);
    return save(f);
}

static void read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    struct sim_flash *f = ctx;
    for (uint32_t i = 0; i < len; i++) {
        uint32_t a = addr + i;
        dst[i] = (a >= BASE && a < BASE + sizeof f->mem) ? f->mem[a - BASE] : 0xFF;
    }
}

bool sim_flash_open(struct sim_flash *f, const char *path)
{
    memset(f, 0, sizeof *f);
    snprintf(f->path, sizeof f->path, "%s", path);
    memset(f->mem, 0xFF, sizeof f->mem);
    FILE *in = fopen(path, "rb");
    if (in != NULL) {
        size_t n = fread(f->mem, 1, sizeof f->mem, in);
        fclose(in);
        if (n != sizeof f->mem) {
            memset(f->mem, 0xFF, sizeof f->mem); /* truncated: a blank chip */
        }
    } else if (!save(f)) {
        return false;
    }
    f->hal = (struct hal_flash){
        .ctx = f,
        .page_size = SIM_FLASH_PAGE,
        .page_addr = {BASE, BASE + SIM_FLASH_PAGE},
        .erase_page = erase_page,
        .program_u16 = program_u16,
        .read = read,
    };
    return true;
}
