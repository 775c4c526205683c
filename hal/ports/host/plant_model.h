/* A servo's model read from a plant file (the .toml files in plants/): the drive train
 * (plant.h), the motor's heat (thermal.h), and the published figures the
 * numbers were derived from, which the model must reproduce.
 *
 * The file is a flat TOML subset, one key a line: `name = "..."`, then
 * `key = number  # where the number comes from`. Every key is required,
 * once, but backlash_deg (0 when left out); a number without a comment is
 * refused, because a model is evidence only when each of its numbers says
 * where it comes from. */
#ifndef HOST_PLANT_MODEL_H
#define HOST_PLANT_MODEL_H

#include <stddef.h>

#include "ports/host/plant.h"
#include "ports/host/thermal.h"

#define PLANT_MODEL_NAME_MAX 64u

struct plant_model {
    char name[PLANT_MODEL_NAME_MAX];
    struct plant_params plant;
    struct thermal_params thermal;
    double published_stall_torque_nm;  /* at supply_v */
    double published_no_load_speed_dps; /* at supply_v */
};

/* The reference servo, as plant_init and thermal_init give it. */
void plant_model_reference(struct plant_model *m);

/* Reads path into m. On failure returns false with m untouched and a
 * sentence in err naming the file, the line and what is wrong. */
bool plant_model_load(const char *path, struct plant_model *m, char *err, size_t err_size);

/* A plant and a thermal model from m, everything at ambient_c. */
void plant_model_apply(const struct plant_model *m, struct plant *pl, struct thermal *t, double ambient_c);

#endif
