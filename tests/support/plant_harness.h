/* The servo harness closed around the physical plant (hal/ports/host/
 * plant.c): once per control tick the plant runs with the last output until
 * now, the encoder reads its angle and the current sensor its current. */
#ifndef TEST_PLANT_HARNESS_H
#define TEST_PLANT_HARNESS_H

#include "ports/host/plant.h"
#include "support/servo_harness.h"

extern struct plant plant;

/* After plant_init and harness_init: the plant drives the encoder from now. */
void plant_harness_attach(void);
/* A fresh plant and servo (servo ID 0, soft start off), attached. */
void plant_harness_start(void);
/* plant_harness_start as a cmocka setup. */
int plant_harness_setup(void **state);

#endif
