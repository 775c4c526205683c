/* Plant files (hal/ports/host/plants): the shipped ones load and reproduce
 * their published figures, the reference's equals the built-in model, and
 * a file that does not say where a number comes from, or is wrong, is
 * refused with a sentence that says what is wrong. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "ports/host/plant_model.h"

static const char *const shipped[] = {"reference_st3215.toml", "micro_9g.toml", "class_60kgcm.toml"};

static void load_shipped(const char *file, struct plant_model *m)
{
    char path[512];
    char err[256] = "";
    snprintf(path, sizeof path, "%s/%s", PLANTS_DIR, file);
    bool ok = plant_model_load(path, m, err, sizeof err);
    if (!ok) {
        print_error("%s\n", err);
    }
    assert_true(ok);
}

static void assert_close(double a, double b, double rel)
{
    if (fabs(a - b) > rel * fabs(b)) {
        print_error("%g is not within %g of %g\n", a, rel, b);
        fail();
    }
}

static void test_shipped_plants_reproduce_their_figures(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof shipped / sizeof shipped[0]; k++) {
        struct plant_model m;
        load_shipped(shipped[k], &m);
        assert_true(strlen(m.name) > 0u);
        struct plant pl;
        struct thermal t;
        plant_model_apply(&m, &pl, &t, 25.0);
        assert_close(plant_stall_torque(&pl), m.published_stall_torque_nm, 0.01);
        assert_close(plant_no_load_speed(&pl) * 180.0 / M_PI, m.published_no_load_speed_dps, 0.01);
        assert_true(t.winding_c == 25.0 && t.p.case_tau_s == m.thermal.case_tau_s);
    }
}

/* Three servo classes, three sizes: the files differ where the classes do. */
static void test_the_classes_differ(void **state)
{
    (void)state;
    struct plant_model micro, reference, large;
    load_shipped("micro_9g.toml", &micro);
    load_shipped("reference_st3215.toml", &reference);
    load_shipped("class_60kgcm.toml", &large);
    struct plant a, b, c;
    struct thermal t;
    plant_model_apply(&micro, &a, &t, 25.0);
    plant_model_apply(&reference, &b, &t, 25.0);
    plant_model_apply(&large, &c, &t, 25.0);
    assert_true(plant_output_inertia(&a) < plant_output_inertia(&b));
    assert_true(plant_output_inertia(&b) < plant_output_inertia(&c));
    assert_true(plant_stall_torque(&a) < plant_stall_torque(&b));
    assert_true(plant_stall_torque(&b) < plant_stall_torque(&c));
    assert_true(micro.plant.supply_v < 5.5 && large.plant.supply_v > 11.0);
}

static void test_the_reference_file_is_the_built_in_model(void **state)
{
    (void)state;
    struct plant_model file, built_in;
    load_shipped("reference_st3215.toml", &file);
    plant_model_reference(&built_in);
    const double *a = (const double *)&file.plant;
    const double *b = (const double *)&built_in.plant;
    for (size_t k = 0; k < sizeof file.plant / sizeof(double); k++) {
        assert_close(a[k], b[k], 1e-3);
    }
    assert_memory_equal(&file.thermal, &built_in.thermal, sizeof file.thermal);
}

/* The reference file with one line replaced (or, where line is NULL,
 * removed), loaded: returns the error, "" when it loaded. */
static const char *load_changed(const char *key, const char *line, struct plant_model *m)
{
    static char err[256];
    char in_path[512];
    snprintf(in_path, sizeof in_path, "%s/reference_st3215.toml", PLANTS_DIR);
    char out_path[] = "/tmp/plant_model_test_XXXXXX";
    int fd = mkstemp(out_path);
    assert_true(fd >= 0);
    FILE *in = fopen(in_path, "r");
    FILE *out = fdopen(fd, "w");
    assert_non_null(in);
    assert_non_null(out);
    char text[512];
    size_t key_len = strlen(key);
    while (fgets(text, sizeof text, in) != NULL) {
        bool is_key = strncmp(text, key, key_len) == 0 && text[key_len] == ' ';
        if (!is_key) {
            fputs(text, out);
        } else if (line != NULL) {
            fprintf(out, "%s\n", line);
        }
    }
    fclose(in);
    fclose(out);
    err[0] = '\0';
    plant_model_load(out_path, m, err, sizeof err);
    unlink(out_path);
    return err;
}

static void assert_refused(const char *key, const char *line, const char *why)
{
    struct plant_model m;
    memset(&m, 0x5a, sizeof m);
    struct plant_model before = m;
    const char *err = load_changed(key, line, &m);
    if (strstr(err, why) == NULL || strstr(err, "plant file /tmp/plant_model_test_") != err) {
        print_error("for '%s': '%s' does not say '%s'\n", line ? line : key, err, why);
        fail();
    }
    assert_memory_equal(&m, &before, sizeof m); /* untouched */
}

static void test_bad_files_are_refused_with_the_reason(void **state)
{
    (void)state;
    assert_refused("gear_ratio", "gear_ratio = 345", "gear_ratio has no source");
    assert_refused("gear_ratio", "gear_ratio = 345 #   ", "source comment is empty");
    assert_refused("gear_ratio", "gear_ratio = fast # mine", "must be a number, not 'fast # mine'");
    assert_refused("gear_ratio", "gear_ratio = 345 kg # mine", "'kg # mine' after the number");
    assert_refused("gear_ratio", "gear_ratio = 0 # mine", "gear_ratio must be from 1 to 10000, not 0");
    assert_refused("gear_ratio", "gear_ratio = nan # mine", "must be a number");
    assert_refused("gear_ratio", "gear_ratio = 345 # a\ngear_ratio = 345 # b", "gear_ratio is given twice");
    assert_refused("gear_ratio", "gear_ratop = 345 # mine", "unknown key 'gear_ratop'");
    assert_refused("gear_ratio", "[gears]", "expected key = value, not '[gears]'");
    assert_refused("gear_ratio", NULL, "gear_ratio is missing");
    assert_refused("name", NULL, "name is missing");
    assert_refused("name", "name = reference", "name is a quoted string");
    /* A number that does not give the published figures is a typo or a
     * model that is not the servo it names. */
    assert_refused("viscous_drag_nm_s_per_rad", "viscous_drag_nm_s_per_rad = 1.481e-6 # mine",
                   "no-load speed of 248.6 deg/s, not the published 312.5 (within 5 %)");
    assert_refused("gear_efficiency", "gear_efficiency = 0.5 # mine", "stall torque of 1.682 N m, not the published 1.912");
}

static void test_a_missing_file_says_so(void **state)
{
    (void)state;
    struct plant_model m;
    char err[256] = "";
    assert_false(plant_model_load("/nonexistent/plant.toml", &m, err, sizeof err));
    assert_string_equal(err, "plant file /nonexistent/plant.toml: cannot be read: No such file or directory");
}

/* A payload on the horn adds to the output's inertia: the same drive
 * accelerates the output half as fast under a payload equal to it. */
static void test_a_payload_slows_the_output(void **state)
{
    (void)state;
    struct plant bare, loaded;
    plant_init(&bare);
    plant_init(&loaded);
    loaded.payload_inertia = plant_output_inertia(&bare);
    assert_close(plant_output_inertia(&loaded), 2.0 * plant_output_inertia(&bare), 1e-12);
    plant_drive(&bare, 32767);
    plant_drive(&loaded, 32767);
    plant_step(&bare, 1e-3);
    plant_step(&loaded, 1e-3);
    assert_true(bare.velocity > 0.0);
    assert_close(loaded.velocity, bare.velocity / 2.0, 0.02);
}

/* The gears' play: reversing, the gears cross it before the output moves;
 * a load holds the output against one flank, so it follows at once. */
static void test_backlash_is_crossed_before_the_output_moves(void **state)
{
    (void)state;
    struct plant pl;
    plant_init(&pl);
    pl.p.backlash_deg = 2.0;
    plant_drive(&pl, 9830); /* 0.3 of the supply */
    plant_step(&pl, 0.3);
    assert_close(pl.play, 1.0 * M_PI / 180.0, 1e-12); /* the gears lead by half the play */
    plant_drive(&pl, -9830);
    while (pl.velocity >= 0.0) { /* the gears carry the output on until they turn */
        plant_step(&pl, 1e-4);
    }
    double held = pl.angle;
    double turned_at = pl.angle + pl.play;
    for (;;) {
        plant_step(&pl, 1e-4);
        if (pl.play <= -1.0 * M_PI / 180.0 + 1e-12) {
            break; /* through: the output goes with them from this step */
        }
        assert_true(pl.angle == held); /* the output stays while the gears cross the play */
    }
    assert_close(turned_at - (pl.angle + pl.play), 2.0 * M_PI / 180.0, 0.02); /* from lead to lag */
    plant_step(&pl, 0.1);
    assert_true(pl.angle < held - 0.01); /* then it follows */
    struct plant loaded;
    plant_init(&loaded);
    loaded.p.backlash_deg = 2.0;
    loaded.load_torque = 0.2;
    plant_drive(&loaded, 9830);
    plant_step(&loaded, 0.01);
    assert_close(loaded.play, 1.0 * M_PI / 180.0, 1e-12); /* pressed against the carrying flank */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shipped_plants_reproduce_their_figures),
        cmocka_unit_test(test_the_classes_differ),
        cmocka_unit_test(test_the_reference_file_is_the_built_in_model),
        cmocka_unit_test(test_bad_files_are_refused_with_the_reason),
        cmocka_unit_test(test_a_missing_file_says_so),
        cmocka_unit_test(test_a_payload_slows_the_output),
        cmocka_unit_test(test_backlash_is_crossed_before_the_output_moves),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
