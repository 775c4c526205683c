#include "ports/host/plant_model.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
/* How closely the model must reproduce its published stall torque and
 * no-load speed: the rounding of a datasheet's figures. */
#define PUBLISHED_TOLERANCE 0.05
#define LINE_MAX_CHARS 512

/* Each number a file gives: its key, where it goes, and what can be. The
 * bounds keep out what the models cannot run (a zero resistance or
 * inertia divides; a thermal time constant under 1 s outruns the thermal
 * model's 10 ms step). */
struct plant_key {
    const char *key;
    size_t offset;
    double lo, hi;
    bool optional; /* 0 when the file leaves it out */
};

#define KEY(name, field, lo, hi) {name, offsetof(struct plant_model, field), lo, hi, false}
#define OPTIONAL_KEY(name, field, lo, hi) {name, offsetof(struct plant_model, field), lo, hi, true}
static const struct plant_key keys[] = {
    KEY("supply_v", plant.supply_v, 1.0, 60.0),
    KEY("resistance_ohm", plant.resistance_ohm, 0.01, 1000.0),
    KEY("torque_constant_nm_per_a", plant.kt, 1e-5, 1.0),
    KEY("gear_ratio", plant.gear_ratio, 1.0, 10000.0),
    KEY("gear_efficiency", plant.efficiency, 0.05, 1.0),
    KEY("rotor_inertia_kg_m2", plant.rotor_inertia, 1e-12, 1e-3),
    KEY("coulomb_drag_nm", plant.drag_coulomb, 0.0, 1.0),
    KEY("viscous_drag_nm_s_per_rad", plant.drag_viscous, 0.0, 1.0),
    KEY("diode_drop_v", plant.diode_v, 0.0, 2.0),
    OPTIONAL_KEY("backlash_deg", plant.backlash_deg, 0.0, 10.0),
    KEY("winding_case_k_per_w", thermal.winding_case_k_per_w, 0.1, 1000.0),
    KEY("winding_tau_s", thermal.winding_tau_s, 1.0, 1e4),
    KEY("case_ambient_k_per_w", thermal.case_ambient_k_per_w, 0.1, 1000.0),
    KEY("case_tau_s", thermal.case_tau_s, 1.0, 1e5),
    KEY("published_stall_torque_nm", published_stall_torque_nm, 1e-4, 1000.0),
    KEY("published_no_load_speed_dps", published_no_load_speed_dps, 1.0, 1e5),
};
#define KEY_COUNT (sizeof keys / sizeof keys[0])

void plant_model_reference(struct plant_model *m)
{
    struct plant pl;
    plant_init(&pl);
    *m = (struct plant_model){.plant = pl.p, .thermal = thermal_reference,
                              .published_stall_torque_nm = 1.912, .published_no_load_speed_dps = 312.5};
    snprintf(m->name, sizeof m->name, "reference ST3215-class servo (built in)");
}

void plant_model_apply(const struct plant_model *m, struct plant *pl, struct thermal *t, double ambient_c)
{
    plant_init(pl);
    pl->p = m->plant;
    thermal_init(t, ambient_c);
    t->p = m->thermal;
}

struct reader {
    const char *path;
    unsigned line;
    char *err;
    size_t err_size;
};

static bool fail(const struct reader *r, const char *fmt, ...)
{
    int n = r->line != 0u ? snprintf(r->err, r->err_size, "plant file %s, line %u: ", r->path, r->line)
                          : snprintf(r->err, r->err_size, "plant file %s: ", r->path);
    if (n >= 0 && (size_t)n < r->err_size) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(r->err + n, r->err_size - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return false;
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') {
        s++;
    }
    size_t n = strlen(s);
    while (n > 0 && strchr(" \t\r\n", s[n - 1]) != NULL) {
        s[--n] = '\0';
    }
    return s;
}

static const struct plant_key *key_named(const char *name)
{
    for (size_t k = 0; k < KEY_COUNT; k++) {
        if (strcmp(name, keys[k].key) == 0) {
            return &keys[k];
        }
    }
    return NULL;
}

/* `"text"`, then nothing or a comment. */
static bool read_name(const struct reader *r, char *value, struct plant_model *m)
{
    char *close = strchr(value + 1, '"');
    if (close == NULL) {
        return fail(r, "the name's closing quote is missing");
    }
    *close = '\0';
    char *rest = trim(close + 1);
    if (*rest != '\0' && *rest != '#') {
        return fail(r, "'%s' after the name", rest);
    }
    if (strlen(value + 1) >= sizeof m->name) {
        return fail(r, "the name is longer than %u characters", PLANT_MODEL_NAME_MAX - 1u);
    }
    snprintf(m->name, sizeof m->name, "%s", value + 1);
    return true;
}

static bool read_number(const struct reader *r, const struct plant_key *k, char *value, struct plant_model *m)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(value, &end);
    if (end == value || errno != 0 || !isfinite(v)) {
        return fail(r, "%s must be a number, not '%s'", k->key, value);
    }
    char *rest = trim(end);
    if (*rest != '#') {
        return fail(r, *rest == '\0' ? "%s has no source: say where the number comes from in a # comment"
                                     : "%s: '%s' after the number", k->key, rest);
    }
    if (*trim(rest + 1) == '\0') {
        return fail(r, "%s's source comment is empty", k->key);
    }
    if (!(v >= k->lo && v <= k->hi)) {
        return fail(r, "%s must be from %g to %g, not %g", k->key, k->lo, k->hi, v);
    }
    memcpy((char *)m + k->offset, &v, sizeof v);
    return true;
}

static bool read_line(const struct reader *r, char *line, struct plant_model *m, bool *seen, bool *named)
{
    char *s = trim(line);
    if (*s == '\0' || *s == '#') {
        return true;
    }
    char *eq = strchr(s, '=');
    if (*s == '[' || eq == NULL) {
        return fail(r, "expected key = value, not '%s'", s);
    }
    *eq = '\0';
    char *key = trim(s);
    char *value = trim(eq + 1);
    if (strcmp(key, "name") == 0) {
        if (*value != '"') {
            return fail(r, "name is a quoted string");
        }
        *named = true;
        return read_name(r, value, m);
    }
    const struct plant_key *k = key_named(key);
    if (k == NULL) {
        return fail(r, "unknown key '%s'", key);
    }
    size_t index = (size_t)(k - keys);
    if (seen[index]) {
        return fail(r, "%s is given twice", key);
    }
    seen[index] = true;
    return read_number(r, k, value, m);
}

/* The parameters must give back the figures they were derived from. */
static bool reproduces_published(const struct reader *r, const struct plant_model *m)
{
    struct plant pl;
    struct thermal t;
    plant_model_apply(m, &pl, &t, 25.0);
    double torque = plant_stall_torque(&pl);
    double speed = plant_no_load_speed(&pl) * 180.0 / PI;
    if (fabs(torque / m->published_stall_torque_nm - 1.0) > PUBLISHED_TOLERANCE) {
        return fail(r, "the parameters give a stall torque of %.4g N m, not the published %.4g (within %.0f %%)",
                    torque, m->published_stall_torque_nm, PUBLISHED_TOLERANCE * 100.0);
    }
    if (fabs(speed / m->published_no_load_speed_dps - 1.0) > PUBLISHED_TOLERANCE) {
        return fail(r, "the parameters give a no-load speed of %.4g deg/s, not the published %.4g (within %.0f %%)",
                    speed, m->published_no_load_speed_dps, PUBLISHED_TOLERANCE * 100.0);
    }
    return true;
}

bool plant_model_load(const char *path, struct plant_model *m, char *err, size_t err_size)
{
    struct reader r = {.path = path, .err = err, .err_size = err_size};
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        return fail(&r, "cannot be read: %s", strerror(errno));
    }
    struct plant_model read = {0};
    bool seen[KEY_COUNT] = {false};
    bool named = false;
    bool ok = true;
    char line[LINE_MAX_CHARS];
    while (ok && fgets(line, sizeof line, f) != NULL) {
        r.line++;
        if (strchr(line, '\n') == NULL && !feof(f)) {
            ok = fail(&r, "longer than %u characters", LINE_MAX_CHARS - 2u);
        } else {
            ok = read_line(&r, line, &read, seen, &named);
        }
    }
    fclose(f);
    r.line = 0u; /* what follows is about the whole file */
    for (size_t k = 0; ok && k < KEY_COUNT; k++) {
        if (!seen[k] && !keys[k].optional) {
            ok = fail(&r, "%s is missing (every key but backlash_deg is required)", keys[k].key);
        }
    }
    if (ok && !named) {
        ok = fail(&r, "name is missing");
    }
    ok = ok && reproduces_published(&r, &read);
    if (ok) {
        *m = read;
    }
    return ok;
}
