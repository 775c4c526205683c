/* The drive train in integers, for the emulated board (no FPU, no soft
 * float in any image): the output's speed follows the duty with the
 * reference plant's 20 ms mechanical time constant, up to its no-load speed
 * (312.5 deg/s at full duty); read through a 12-bit encoder. One step per
 * control tick. */
#ifndef QEMU_PLANT_FIXED_H
#define QEMU_PLANT_FIXED_H

#include <stdbool.h>
#include <stdint.h>

struct plant_fixed {
    int32_t position_q8;  /* encoder counts, Q8, multi-turn */
    int32_t velocity_q8;  /* counts per tick, Q8 */
    int16_t duty;         /* Q15 */
    bool coast;
};

void plant_fixed_step(struct plant_fixed *p);
uint16_t plant_fixed_encoder(const struct plant_fixed *p);
/* Winding current in mA (I = (V d - back-EMF) / R), magnitude. */
uint16_t plant_fixed_current_ma(const struct plant_fixed *p);

#endif
