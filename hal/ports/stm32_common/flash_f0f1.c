#include "ports/stm32_common/flash_f0f1.h"

#include "ports/stm32_common/stm32_core_regs.h"

static void unlock(void)
{
    if (FLASH_CR & FLASH_CR_LOCK) {
        FLASH_KEYR = FLASH_KEY1;
        FLASH_KEYR = FLASH_KEY2;
    }
}

/* Waits for the operation, clears its flags, says whether it succeeded. */
static bool finish(void)
{
    while (FLASH_SR & FLASH_SR_BSY) {
    }
    uint32_t sr = FLASH_SR;
    FLASH_SR = FLASH_SR_EOP | FLASH_SR_PGERR | FLASH_SR_WRPRTERR;
    FLASH_CR = FLASH_CR_LOCK;
    return (sr & (FLASH_SR_PGERR | FLASH_SR_WRPRTERR)) == 0u;
}

static bool erase_page(void *ctx, uint32_t addr)
{
    const struct hal_flash *f = ctx;
    unlock();
    FLASH_CR = FLASH_CR_PER;
    FLASH_AR = addr;
    FLASH_CR = FLASH_CR_PER | FLASH_CR_STRT;
    bool ok = finish();
    for (uint32_t i = 0; ok && i < f->page_size; i += 4u) {
        ok = REG32(addr + i) == 0xFFFFFFFFu;
    }
    return ok;
}

/* A half-word at a time (RM0008 3.3.3, RM0360 3.2.2): the write block. */
static bool program(void *ctx, uint32_t addr, const uint8_t *data)
{
    (void)ctx;
    uint16_t value = (uint16_t)(data[0] | (uint16_t)(data[1] << 8));
    volatile uint16_t *cell = (volatile uint16_t *)(uintptr_t)addr;
    unlock();
    FLASH_CR = FLASH_CR_PG;
    *cell = value;
    bool ok = finish();
    return ok && *cell == value;
}

/* A half-word a load where the address is even (the flash's program unit,
 * which program() reads back the same way), and a store where the
 * destination is even too (a fault history entry into ReadFaults' answer,
 * which has 30 us on the M0). Volatile: what an erase or a program changed
 * behind the compiler's back is read anew. */
#ifndef STARTUP_BOOTLOADER
typedef uint16_t __attribute__((may_alias)) any_half; /* stores into any object */
#endif

void flash_f0f1_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    uint32_t i = 0;
#ifndef STARTUP_BOOTLOADER
    /* Not in the bootloader (-Oz, LTO): with the half-word loop the F030's
     * bootloader went silent after UpdateEnter in 3 of 6 runs on the virtual
     * board; a byte a load, 0 of 6. Its reads are not timed. */
    if (((addr | (uintptr_t)dst) & 1u) == 0u) {
        const volatile uint16_t *half = (const volatile uint16_t *)(uintptr_t)addr;
        any_half *to = (any_half *)(void *)dst;
        for (; i + 2u <= len; i += 2u) {
            to[i / 2u] = half[i / 2u];
        }
    }
#endif
    const volatile uint8_t *src = (const volatile uint8_t *)(uintptr_t)addr;
    for (; i < len; i++) {
        dst[i] = src[i];
    }
}

void flash_f0f1_init(struct hal_flash *f, uint32_t page_size, uint32_t page0, uint32_t page1)
{
    *f = (struct hal_flash){
        .ctx = f,
        .page_size = page_size,
        .page_addr = {page0, page1},
        .erase_page = erase_page,
        .write_block = 2,
        .program = program,
        .read = flash_f0f1_read,
    };
}
