#include "support/plant_harness.h"

#include <math.h>

#include "support/by_name.h"

struct plant plant;
static uint32_t plant_time_us;

static uint16_t plant_encoder_model(void *model)
{
    (void)model;
    if (hal.coasting) {
        plant_coast(&plant);
    } else {
        plant_drive(&plant, hal.duty);
    }
    plant_step(&plant, (hal.now_us - plant_time_us) * 1e-6);
    plant_time_us = hal.now_us;
    hal.sensors.current = (uint16_t)lround(fabs(plant.current) * 1000.0);
    return plant_encoder(&plant);
}

void plant_harness_attach(void)
{
    plant_time_us = hal.now_us;
    hal.encoder_model = plant_encoder_model;
}

void plant_harness_start(void)
{
    plant_init(&plant);
    harness_init();
    plant_harness_attach();
    harness_write_item(0, ITEM_SOFT_START_ON, 0); /* no soft start */
}

int plant_harness_setup(void **state)
{
    (void)state;
    plant_harness_start();
    return 0;
}
