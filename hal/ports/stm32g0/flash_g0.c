#include "ports/stm32g0/flash_g0.h"

#include "ports/stm32g0/flash_g0_logic.h"
#include "ports/stm32g0/stm32g0_regs.h"

static volatile uint32_t ecc_errors;
static bool last_read_failed;

/* Before an operation (RM0444 3.3.7, 3.3.8): none under way, no error
 * left from an earlier one, the interface unlocked (KEYR, 3.3.6). */
static void begin(void)
{
    while (G0_FLASH_SR & (G0_FLASH_SR_BSY1 | G0_FLASH_SR_CFGBSY)) {
    }
    G0_FLASH_SR = G0_FLASH_SR_ERRORS | G0_FLASH_SR_EOP;
    if (G0_FLASH_CR & G0_FLASH_CR_LOCK) {
        G0_FLASH_KEYR = G0_FLASH_KEY1;
        G0_FLASH_KEYR = G0_FLASH_KEY2;
    }
}

/* Waits for it (CFGBSY clears when it ends), locks, says whether it succeeded. */
static bool finish(void)
{
    while (G0_FLASH_SR & (G0_FLASH_SR_BSY1 | G0_FLASH_SR_CFGBSY)) {
    }
    uint32_t sr = G0_FLASH_SR;
    G0_FLASH_SR = G0_FLASH_SR_ERRORS | G0_FLASH_SR_EOP;
    G0_FLASH_CR = G0_FLASH_CR_LOCK;
    return !flash_g0_failed(sr, G0_FLASH_SR_ERRORS);
}

/* ctx: the struct flash_g0 of the chip. */
static bool erase_page(void *ctx, uint32_t addr)
{
    const struct flash_g0 *chip = ctx;
    uint32_t page;
    if (!flash_g0_page_of(chip->base, chip->page_size, chip->pages, addr, &page)) {
        return false;
    }
    begin();
    G0_FLASH_CR = G0_FLASH_CR_PER | (page << G0_FLASH_CR_PNB_SHIFT);
    G0_FLASH_CR = G0_FLASH_CR_PER | (page << G0_FLASH_CR_PNB_SHIFT) | G0_FLASH_CR_STRT;
    bool ok = finish();
    for (uint32_t i = 0; ok && i < chip->page_size; i += 4u) {
        ok = REG32(addr + i) == 0xFFFFFFFFu;
    }
    return ok;
}

/* A double word (RM0444 3.3.7): PG set, the first word then the second;
 * the flash programs the pair with its ECC once the second is written. */
static bool program(void *ctx, uint32_t addr, const uint8_t *data)
{
    (void)ctx;
    if (!flash_g0_unit_aligned(addr)) {
        return false;
    }
    uint32_t lo = flash_g0_word(data);
    uint32_t hi = flash_g0_word(data + 4);
    begin();
    G0_FLASH_CR = G0_FLASH_CR_PG;
    REG32(addr) = lo;
    REG32(addr + 4u) = hi;
    bool ok = finish();
    return ok && REG32(addr) == lo && REG32(addr + 4u) == hi;
}

void flash_g0_read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    uint32_t before = ecc_errors;
    uint32_t i = 0;
#ifndef STARTUP_BOOTLOADER /* a word a load where aligned; the bootloader's are not timed */
    if ((addr & 3u) == 0u) {
        for (; i + 4u <= len; i += 4u) {
            uint32_t v = REG32(addr + i);
            dst[i] = (uint8_t)v;
            dst[i + 1u] = (uint8_t)(v >> 8);
            dst[i + 2u] = (uint8_t)(v >> 16);
            dst[i + 3u] = (uint8_t)(v >> 24);
        }
    }
#endif
    const volatile uint8_t *src = (const volatile uint8_t *)(uintptr_t)addr;
    for (; i < len; i++) {
        dst[i] = src[i];
    }
    last_read_failed = ecc_errors != before;
    if (last_read_failed) {
        /* A torn double word in what was read (the NMI came between):
         * what it held is not to be trusted, nor is its record. */
        for (i = 0; i < len; i++) {
            dst[i] = 0;
        }
    }
}

bool flash_g0_read_failed(void)
{
    return last_read_failed;
}

/* used: the NMI handler calls it from assembly, which link-time optimisation
 * does not see */
__attribute__((used)) bool flash_g0_nmi_ecc(void)
{
    if (!(G0_FLASH_ECCR & G0_FLASH_ECCR_ECCD)) {
        return false;
    }
    G0_FLASH_ECCR = G0_FLASH_ECCR_ECCD; /* written 1, cleared (RM0444 3.7.7) */
    ecc_errors++;
    return true;
}

uint32_t flash_g0_ecc_errors(void)
{
    return ecc_errors;
}

void flash_g0_init(struct hal_flash *f, struct flash_g0 *chip, uint32_t page0, uint32_t page1)
{
    *f = (struct hal_flash){
        .ctx = chip,
        .page_size = chip->page_size,
        .page_addr = {page0, page1},
        .erase_page = erase_page,
        .write_block = FLASH_G0_UNIT,
        .program = program,
        .read = flash_g0_read,
    };
}
