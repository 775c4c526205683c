#define _POSIX_C_SOURCE 200809L
#include "ports/host/sim_flash.h"

#include <fcntl.h>
#include <string.h>
#include <unistd.h>

/* Writes len bytes of the chip at offset through to the file. */
static bool save(const struct sim_flash *f, uint32_t offset, uint32_t len)
{
    return pwrite(f->fd, &f->mem[offset], len, (off_t)offset) == (ssize_t)len;
}

static bool erase_page(void *ctx, uint32_t addr)
{
    struct sim_flash *f = ctx;
    if (addr < f->base || addr - f->base >= f->size || (addr - f->base) % SIM_FLASH_PAGE != 0u) {
        return false;
    }
    f->stall_us += SIM_FLASH_ERASE_US;
    if (f->fail_erases != 0u) {
        f->fail_erases--;
        return false;
    }
    memset(&f->mem[addr - f->base], 0xFF, SIM_FLASH_PAGE);
    return save(f, addr - f->base, SIM_FLASH_PAGE);
}

/* Half-words, as the reference board's STM32F1. */
static bool program(void *ctx, uint32_t addr, const uint8_t *data)
{
    struct sim_flash *f = ctx;
    if (addr < f->base || addr - f->base > f->size - 2u || (addr & 1u)) {
        return false;
    }
    uint8_t *cell = &f->mem[addr - f->base];
    if (cell[0] != 0xFF || cell[1] != 0xFF) {
        return false;
    }
    f->stall_us += SIM_FLASH_PROGRAM_US;
    if (f->fail_programs != 0u) {
        f->fail_programs--;
        return false;
    }
    cell[0] = data[0];
    cell[1] = data[1];
    return save(f, addr - f->base, 2);
}

static void flash_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    struct sim_flash *f = ctx;
    for (uint32_t i = 0; i < len; i++) {
        uint32_t a = addr + i;
        dst[i] = (a >= f->base && a - f->base < f->size) ? f->mem[a - f->base] : 0xFF;
    }
}

bool sim_flash_open(struct sim_flash *f, const char *path, uint32_t base, uint32_t pages,
                    uint8_t *mem)
{
    *f = (struct sim_flash){.mem = mem, .base = base, .size = pages * SIM_FLASH_PAGE};
    memset(f->mem, 0xFF, f->size);
    f->fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (f->fd < 0) {
        return false;
    }
    if (pread(f->fd, f->mem, f->size, 0) != (ssize_t)f->size) {
        f->created = true;
        memset(f->mem, 0xFF, f->size); /* new or truncated: a blank chip */
        if (!save(f, 0, f->size)) {
            return false;
        }
    }
    f->hal = hal_flash_two_pages(f, SIM_FLASH_PAGE, base, erase_page, program, flash_read);
    return true;
}
