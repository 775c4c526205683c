/* The winding's estimate (protection/winding.c) against the closed form of
 * its model in double precision, and the derating it gives. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "protection/winding.h"
#include "sensors/ntc.h"

/* The reference motor (firmware/boards/stm32f103/board.h). */
#define R_OHM 2.741
#define RTH_K_PER_W 3.1
#define TAU_S 12.0
static const struct sensor_calibration board = {
    .winding_heat_k = (uint16_t)(2741.0 * 3100.0 * 268435456.0 / 1e12 + 0.5),
    .winding_step_k = (uint16_t)(65536.0 * 0.080 / TAU_S + 0.5),
    .winding_limit_decic = 1250,
};
static const uint16_t case_limit_adc = 651; /* item 41's factory value, about 75 degC */

/* Runs the model for seconds (whole 80 ms steps) at a steady current;
 * returns the estimate. */
static double run(struct winding_model *w, uint16_t current_ma, uint16_t case_adc, double seconds)
{
    unsigned steps = (unsigned)(seconds / 0.080 + 0.5);
    for (unsigned i = 0; i < steps; i++) {
        while (!winding_sample(w, current_ma)) {
        }
        winding_step(w, &board, case_adc, case_limit_adc);
    }
    return w->winding_decic / 10.0;
}

static void test_heat_up_and_cool_down_follow_the_model(void **state)
{
    (void)state;
    struct winding_model w;
    winding_init(&w);
    const uint16_t case_adc = 2048; /* 25 degC */
    double case_c = ntc_decicelsius(case_adc) / 10.0;
    const double amps = 2.0;
    double settle = amps * amps * R_OHM * RTH_K_PER_W; /* 34.0 K */
    double worst = 0.0;
    for (int s = 2; s <= 60; s += 2) { /* five time constants of heating */
        double got = run(&w, 2000, case_adc, 2.0);
        double want = case_c + settle * (1.0 - exp(-s / TAU_S));
        worst = fmax(worst, fabs(got - want));
    }
    double hot = w.rise_q16 / 65536.0;
    for (int s = 2; s <= 60; s += 2) { /* and of cooling */
        double got = run(&w, 0, case_adc, 2.0);
        double want = case_c + hot * exp(-s / TAU_S);
        worst = fmax(worst, fabs(got - want));
    }
    print_message("# 2 A for 60 s, then 0 for 60 s: worst error %.2f degC\n", worst);
    assert_true(worst < 0.5);
}

static void test_the_largest_current_does_not_overflow(void **state)
{
    (void)state;
    struct winding_model w;
    winding_init(&w);
    double hot = run(&w, 65535, 2048, 120.0);
    /* clamped at 16.383 A: the settled rise is 500 degC, the clamp */
    assert_true(hot > 400.0 && hot < 530.0);
    assert_true(w.rise_q16 > 0);
}

static void test_derating_falls_in_steps_to_the_floor(void **state)
{
    (void)state;
    struct winding_model w;
    winding_init(&w);
    run(&w, 0, 2048, 1.0);
    assert_int_equal(w.level, DERATE_LEVELS);
    assert_int_equal(winding_power_cap(&w, 10000), 0); /* none */
    /* The case 6.4 degC below item 41's temperature: half the band left. */
    int16_t limit_decic = ntc_decicelsius(case_limit_adc);
    run(&w, 0, ntc_adc((int16_t)(limit_decic - 64)), 0.08);
    assert_int_equal(w.level, 8);
    assert_int_equal(winding_power_cap(&w, 10000), 5000);
    /* At the limit: the floor, never none. */
    run(&w, 0, case_limit_adc, 0.08);
    assert_int_equal(w.level, DERATE_FLOOR);
    assert_int_equal(winding_power_cap(&w, 10000), 625);
    assert_int_equal(winding_power_cap(&w, 8), 1);
}

static void test_a_hot_winding_derates_before_its_limit(void **state)
{
    (void)state;
    struct winding_model w;
    winding_init(&w);
    /* 3 A: 24.7 W, a rise of 76.5 K over a 40 degC case, heading for
     * 116.5 degC: inside the winding's band (99.4 to 125 degC). */
    run(&w, 3000, ntc_adc(400), 60.0);
    assert_true(w.winding_decic > 1100 && w.winding_decic < 1170);
    assert_true(w.level < DERATE_LEVELS && w.level > DERATE_FLOOR);
}

static void test_no_model_means_no_winding_derating(void **state)
{
    (void)state;
    const struct sensor_calibration none = {0};
    struct winding_model w;
    winding_init(&w);
    for (int i = 0; i < 100; i++) {
        while (!winding_sample(&w, 3000)) {
        }
        winding_step(&w, &none, 2048, case_limit_adc);
    }
    assert_int_equal(w.rise_q16, 0);
    assert_int_equal(w.level, DERATE_LEVELS);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_heat_up_and_cool_down_follow_the_model),
        cmocka_unit_test(test_the_largest_current_does_not_overflow),
        cmocka_unit_test(test_derating_falls_in_steps_to_the_floor),
        cmocka_unit_test(test_a_hot_winding_derates_before_its_limit),
        cmocka_unit_test(test_no_model_means_no_winding_derating),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
