/* The STM32G031's flash as its driver sees it (RM0444 3), for
 * hal/ports/stm32g0/flash_g0.c compiled on the host: this header is
 * included ahead of it (tests/CMakeLists.txt), so the driver's REG32 goes
 * through g0_model_reg. The array is mapped at an address below 4 GB, so
 * the driver's own loads read it as they read flash on the chip; the
 * interface's registers (SR, CR, ECCR) are the model's. A program step
 * takes the two words written with PG set, a double word at an 8-byte
 * boundary, and programs it when the driver next touches the interface; a
 * not-erased double word is refused (PROGERR). A power cut at a step can
 * tear the double word: the first word alone, or the data without its ECC
 * bits. Either reads back as an ECC double error: a word load of it
 * raises the NMI, which the model takes by calling flash_g0_nmi_ecc as
 * the startup's handler does (byte loads, which the driver uses only for
 * a read's unaligned tail, do not). */
#ifndef TEST_FLASH_G0_MODEL_H
#define TEST_FLASH_G0_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "ports/stm32_common/stm32_core_regs.h"

#undef REG32
#define REG32(addr) (*g0_model_reg((uint32_t)(addr)))

#define G0_MODEL_PAGE 2048u
#define G0_MODEL_PAGES 32u
#define G0_MODEL_UNITS (G0_MODEL_PAGE * G0_MODEL_PAGES / 8u)

/* What a cut program step leaves. */
enum g0_tear {
    G0_TEAR_FIRST_WORD, /* the first word programmed, the second not */
    G0_TEAR_ECC,        /* both words, the ECC bits not */
};

struct g0_flash_model {
    uint8_t *mem;  /* the array: G0_MODEL_PAGES pages from base */
    uint32_t base;
    bool torn[G0_MODEL_UNITS];
    uint32_t sr, cr, eccr;
    uint32_t latch[2];    /* the words a program step was given */
    uint32_t latch_addr;
    uint32_t latched;
    long steps;           /* program and erase steps so far */
    long cut_at;          /* the step the power fails in; -1 never */
    enum g0_tear tear;
    bool dead;            /* after the cut: nothing changes any more */
    uint32_t programs;    /* double words programmed */
    uint32_t erases[G0_MODEL_PAGES];
    uint32_t nmis;        /* ECC double errors raised */
    bool misuse;          /* a step the chip would refuse or not do */
};

/* The model, erased, its array mapped (false where no address below 4 GB
 * could be had). */
bool g0_model_init(struct g0_flash_model *m);
void g0_model_power_on(struct g0_flash_model *m);
/* The address of the double word unit of the array. */
uint32_t g0_model_addr(const struct g0_flash_model *m, uint32_t page, uint32_t offset);

volatile uint32_t *g0_model_reg(uint32_t addr);

#endif
