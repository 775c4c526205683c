/* What a board's C code derives from its board.h, which holds plain numbers
 * so that the linker scripts (hal/ports/stm32_common/linker/app.ld.in and boot.ld.in,
 * through the C preprocessor) and servoctl can read it too. Checked here,
 * at build time: the map must fit together. */
#ifndef BOARD_DERIVED_H
#define BOARD_DERIVED_H

/* RAM a reset keeps, left out of both images' linker scripts: the word
 * that keeps the bootloader last (boot_jump.h), the kept record at the
 * start (ports/stm32_common/kept_ram.h). */
#define BOARD_RAM_KEPT 64
/* The register whose clearing turns the bridge's outputs off at once, for
 * the fault handler's first store (ports/stm32_common/core_vectors.h): TIM3's CCER
 * unless the board says otherwise (a timer's enable bits are not preloaded,
 * RM0008 15.4.9, RM0360 13.4.9). */
#ifndef BOARD_BRIDGE_OFF_REG
#define BOARD_BRIDGE_OFF_REG 0x40000420
#endif

#ifndef BOARD_FOR_LINKER
#include <stdint.h>

/* The end of RAM: the word below it keeps the bootloader (boot_jump.h). */
#define BOARD_RAM_END ((uint32_t)BOARD_RAM_BASE + (uint32_t)BOARD_RAM_SIZE)

/* Initialiser of a struct sensor_calibration for the board's front end. */
#define BOARD_SENSOR_CALIBRATION                                           \
    {                                                                      \
        .supply_mv_q12 = SENSOR_Q12_FROM_MICRO(BOARD_SUPPLY_UV_PER_COUNT),  \
        .current_ma_q12 = SENSOR_Q12_FROM_MICRO(BOARD_CURRENT_UA_PER_COUNT), \
        .winding_heat_k = BOARD_WINDING_HEAT_K,                            \
        .winding_step_k = BOARD_WINDING_STEP_K,                            \
        .winding_limit_decic = BOARD_WINDING_LIMIT_DECIC,                  \
    }
/* The winding model's constants (protection/winding.h): R (mOhm) x R_wc
 * (mK/W) x 16 x 65536 x 256 / 10^12, and 65536 x 80 ms / tau. */
#define BOARD_WINDING_HEAT_K                                                                 \
    ((uint16_t)(((uint64_t)BOARD_MOTOR_MOHM * BOARD_WINDING_CASE_MK_PER_W * (1ull << 28) +   \
                 500000000000ull) / 1000000000000ull))
#define BOARD_WINDING_STEP_K ((uint16_t)((65536u * 80u + BOARD_WINDING_TAU_MS / 2u) / BOARD_WINDING_TAU_MS))
_Static_assert(BOARD_WINDING_HEAT_K < 4096 && BOARD_WINDING_TAU_MS >= 1300u,
               "board.h: the winding model's products fit 32 bits (winding.c)");
_Static_assert(BOARD_SUPPLY_UV_PER_COUNT < 16000 && BOARD_CURRENT_UA_PER_COUNT < 16000,
               "board.h: a count is worth less than 16 mV (16 mA), the Q12 scale's range");

_Static_assert(BOARD_SLOT_BASE == BOARD_FLASH_BASE + BOARD_BOOT_SIZE,
               "board.h: the slot starts where the bootloader ends");
_Static_assert(BOARD_RX_RING_BYTES >= 256 && (BOARD_RX_RING_BYTES & (BOARD_RX_RING_BYTES - 1)) == 0 &&
                   BOARD_BOOT_RX_RING_BYTES >= 256 &&
                   (BOARD_BOOT_RX_RING_BYTES & (BOARD_BOOT_RX_RING_BYTES - 1)) == 0,
               "board.h: the receive rings are powers of two, 256 bytes or more");
#ifdef BOARD_FAULT_PAGE0
_Static_assert(BOARD_SLOT_BASE + BOARD_SLOT_PAGES * BOARD_FLASH_PAGE <= BOARD_FAULT_PAGE0 &&
                   BOARD_FAULT_PAGE1 == BOARD_FAULT_PAGE0 + BOARD_FLASH_PAGE &&
                   BOARD_FAULT_PAGE1 + BOARD_FLASH_PAGE <= BOARD_CONFIG_PAGE0,
               "board.h: the slot, then the fault history's two adjacent pages, then the store");
#endif
#ifdef BOARD_CONFIG_PAGE0
_Static_assert(BOARD_SLOT_BASE + BOARD_SLOT_PAGES * BOARD_FLASH_PAGE <= BOARD_CONFIG_PAGE0,
               "board.h: the slot ends before the config store");
_Static_assert(BOARD_CONFIG_PAGE1 == BOARD_CONFIG_PAGE0 + BOARD_FLASH_PAGE,
               "board.h: the config store is two adjacent pages");
#endif
#endif

#endif
