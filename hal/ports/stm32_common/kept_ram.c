#include "ports/stm32_common/kept_ram.h"

#include <string.h>

#ifdef STM32_FAMILY_G0
#include "ports/stm32g0/stm32g0_regs.h" /* its RCC_CSR: another offset, another RMVF */
#else
#include "ports/stm32_common/stm32_core_regs.h"
#endif
#include "runtime/crc32.h"

_Static_assert(sizeof(struct kept_ram) <= 64u - 4u, "the kept record fits the kept bytes (board_derived.h) before the stay word");

static uint32_t kept_crc(const struct kept_ram *k)
{
    return crc32((const uint8_t *)k, offsetof(struct kept_ram, crc));
}

void kept_seal(struct kept_ram *k)
{
    k->magic = KEPT_MAGIC;
    k->crc = kept_crc(k);
}

/* Which of item 73's counts each kind from HAL_RESET_FIRMWARE_FAULT on adds to. */
static const uint8_t KIND_COUNT[] = {HAL_COUNT_FIRMWARE_FAULT, HAL_COUNT_WATCHDOG, HAL_COUNT_OTHER,
                                     HAL_COUNT_BROWN_OUT, HAL_COUNT_OTHER, HAL_COUNT_OTHER};
/* The kinds that are the firmware's own failures (not the supply's, not
 * the pin's): they count towards safe mode. */
#define OWN_KINDS ((1u << HAL_RESET_FIRMWARE_FAULT) | (1u << HAL_RESET_WATCHDOG) | \
                   (1u << HAL_RESET_SOFTWARE) | (1u << HAL_RESET_LOW_POWER))

static uint8_t saturating_inc(uint8_t n)
{
    return (uint8_t)(n + (n < UINT8_MAX));
}

void reset_classify(uint32_t csr, struct kept_ram *k)
{
    bool held = k->magic == KEPT_MAGIC && k->crc == kept_crc(k);
    if (!held) {
        memset(k, 0, sizeof *k);
    }
    /* The reset flags in the order they explain a reset (tests, not a
     * table: smaller on the M0): every reset sets PINRSTF (the chip drives
     * its own NRST low), so alone it means the pin; a power-on flag with
     * the record held is a brown-out. */
    uint8_t kind = HAL_RESET_POWER_ON;
    if (csr & (RCC_CSR_IWDGRSTF | RCC_CSR_WWDGRSTF)) {
        kind = HAL_RESET_WATCHDOG;
    } else if (csr & RCC_CSR_SFTRSTF) {
        kind = HAL_RESET_SOFTWARE;
    } else if (csr & RCC_CSR_LPWRRSTF) {
        kind = HAL_RESET_LOW_POWER;
    } else if (csr & RCC_CSR_PORRSTF) {
        kind = HAL_RESET_BROWN_OUT;
    } else if (csr & RCC_CSR_PINRSTF) {
        kind = HAL_RESET_PIN;
    }
    if (kind == HAL_RESET_BROWN_OUT && !held) {
        kind = HAL_RESET_POWER_ON;
    }
    if (k->note != KEPT_NONE) {
        kind = k->note == KEPT_FAULT ? HAL_RESET_FIRMWARE_FAULT : HAL_RESET_PLANNED;
    }
    struct hal_reset *r = &k->reset;
    r->kind = kind;
    if (kind != HAL_RESET_FIRMWARE_FAULT) { /* a fault's details only with a fault */
        memset(&r->pc, 0, sizeof *r - offsetof(struct hal_reset, pc));
    }
    if (kind < HAL_RESET_FIRMWARE_FAULT) {
        r->in_row = 0;
    } else {
        uint8_t *count = &r->counts[KIND_COUNT[kind - HAL_RESET_FIRMWARE_FAULT]];
        *count = saturating_inc(*count);
        if (OWN_KINDS >> kind & 1u) {
            r->in_row = saturating_inc(r->in_row);
        }
    }
    k->note = KEPT_NONE;
    kept_seal(k);
}

const struct hal_reset *reset_cause_take(void)
{
    reset_classify(RCC_CSR, &_kept_ram);
    RCC_CSR |= RCC_CSR_RMVF;
    return &_kept_ram.reset;
}

void kept_note_planned(uint8_t id, uint8_t baud_index)
{
    _kept_ram.note = KEPT_PLANNED;
    _kept_ram.link_id = id;
    _kept_ram.link_baud = baud_index;
    kept_seal(&_kept_ram);
}

bool kept_link(uint8_t *id, uint8_t *baud_index)
{
    const struct kept_ram *k = &_kept_ram;
    if (k->magic != KEPT_MAGIC || k->note != KEPT_PLANNED) {
        return false;
    }
    *id = k->link_id;
    *baud_index = k->link_baud;
    return true;
}

void kept_healthy(void)
{
    /* In safe mode a quiet run proves nothing: the output is held off. */
    if (_kept_ram.reset.in_row != 0u && _kept_ram.reset.in_row < HAL_SAFE_MODE_RESETS) {
        _kept_ram.reset.in_row = 0;
        kept_seal(&_kept_ram);
    }
}
