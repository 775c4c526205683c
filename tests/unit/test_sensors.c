/* Sensor scaling, filtering and turns, and the generated NTC table, against appendix 5.1's exact
 * formula (floating point only here, in the test). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "sensors/ntc.h"
#include "sensors/scaling.h"

static double exact_adc(double celsius)
{
    double rt = 10000.0 * exp(3435.0 * (1.0 / (273.15 + celsius) - 1.0 / (273.15 + 25.0)));
    return rt * 4096.0 / (rt + 10000.0);
}

static double exact_celsius(double adc)
{
    double rt = 10000.0 * adc / (4096.0 - adc);
    return 1.0 / (log(rt / 10000.0) / 3435.0 + 1.0 / (273.15 + 25.0)) - 273.15;
}

static void test_table_falls_and_matches_the_formula(void **state)
{
    (void)state;
    for (int i = 1; i < NTC_TABLE_SIZE; i++) {
        assert_true(ntc_adc_at[i] < ntc_adc_at[i - 1]);
    }
    double worst_c = 0, worst_adc = 0;
    for (int t10 = -200; t10 <= 1200; t10++) {
        double c = t10 / 10.0;
        double adc = exact_adc(c);
        double back = ntc_decicelsius((uint16_t)lround(adc)) / 10.0;
        double err_c = fabs(back - exact_celsius(lround(adc)));
        /* degC to ADC, judged in degC: the curve is steep near 25 degC. */
        double err_adc = fabs(exact_celsius(ntc_adc((int16_t)t10)) - c);
        worst_c = err_c > worst_c ? err_c : worst_c;
        worst_adc = err_adc > worst_adc ? err_adc : worst_adc;
    }
    printf("# -20..120 degC: worst %.3f degC ADC to degC, %.3f degC degC to ADC\n", worst_c,
           worst_adc);
    assert_true(worst_c <= 0.2);
    assert_true(worst_adc <= 0.2);
}

static void test_protocol_reference_points(void **state)
{
    (void)state;
    assert_int_equal(ntc_adc(250), 2048);           /* 25 degC: R_t = R_1 */
    /* docs/protocol.md: 651 is "about 75 degC". */
    assert_true(fabs(ntc_decicelsius(651) / 10.0 - exact_celsius(651)) <= 0.2);
    assert_in_range(ntc_decicelsius(2048), 249, 251);
    /* Beyond the table's ends: clamped. */
    assert_int_equal(ntc_decicelsius(4095), -400);
    assert_int_equal(ntc_decicelsius(0), 1500);
    assert_int_equal(ntc_adc(-1000), ntc_adc_at[0]);
    assert_int_equal(ntc_adc(3000), ntc_adc_at[NTC_TABLE_SIZE - 1]);
}

/* The reference board: 3.3 V, 11:1 supply divider, 0.5 V/A current sense. */
static const struct sensor_calibration board = {.supply_mv_q12 = SENSOR_Q12_FROM_MICRO(8862u),
                                                .current_ma_q12 = SENSOR_Q12_FROM_MICRO(1611u)};
/* The board's current amplifier reads 12 at no current (item 91). */
enum { CURRENT_ZERO = 12 };

/* A filter primed by one tick of raw, the current amplifier reading zero
 * at zero: the readings as they are, in units. */
static struct sensor_readings primed_at(const struct sensor_calibration *cal, uint16_t zero,
                                        struct sensor_raw raw)
{
    struct sensor_filter f = {.current_zero = zero};
    sensors_update(&f, cal, &raw);
    return f.out;
}

static struct sensor_readings primed(const struct sensor_calibration *cal, struct sensor_raw raw)
{
    return primed_at(cal, 0, raw);
}

static void test_scaling_to_units(void **state)
{
    (void)state;
    struct sensor_readings r = primed_at(&board, CURRENT_ZERO, (struct sensor_raw){.supply = 835, .current = 632, .ntc = 1500});
    assert_int_equal(r.voltage_mv, 7400);  /* 835 x 8.862 mV = 7399.8, rounded */
    assert_int_equal(r.current_ma, 999);   /* (632 - 12) x 1.611 mA = 998.8, rounded */
    assert_int_equal(r.power_mw, 7393); /* 7400 mV x 999 mA = 7392.6, to within 1/1024 V */
    assert_int_equal(r.temperature_adc, 1500);
    /* Below the amplifier's zero: no current, not a wrap-around. */
    r = primed_at(&board, CURRENT_ZERO, (struct sensor_raw){.supply = 4095, .current = 3, .ntc = 0});
    assert_int_equal(r.current_ma, 0);
    assert_int_equal(r.voltage_mv, 36290); /* 4095 x 8.862 mV = 36289.9 */
}

/* Power without a division: within 1 mW per ampere, plus rounding, of
 * mV x mA / 1000 across the supplies and currents a servo sees. */
static void test_power_is_the_product_to_within_a_milliwatt_an_ampere(void **state)
{
    (void)state;
    const struct sensor_calibration unit = {.supply_mv_q12 = 4096, .current_ma_q12 = 4096};
    for (uint32_t mv = 0; mv <= 30000; mv += 97) {
        for (uint32_t ma = 0; ma <= 6000; ma += 61) {
            struct sensor_readings r =
                primed(&unit, (struct sensor_raw){.supply = (uint16_t)mv, .current = (uint16_t)ma});
            double exact = (double)mv * ma / 1000.0;
            double allowed = ma / 1000.0 + 0.5;
            if (exact >= 65535.0) {
                assert_int_equal(r.power_mw, 65535); /* saturates */
            } else if (r.power_mw < exact - allowed - 1e-9 || r.power_mw > exact + allowed + 1e-9) {
                fail_msg("%u mV x %u mA: %u mW, not %.1f", mv, ma, r.power_mw, exact);
            }
        }
    }
}

static const struct sensor_calibration unit = {.supply_mv_q12 = 4096, .current_ma_q12 = 4096};

/* A tick of raw samples; the slot it served. */
static enum sense_slot tick(struct sensor_filter *f, uint16_t mv, uint16_t ma, uint16_t ntc)
{
    return sensors_update(f, &unit, &(struct sensor_raw){.supply = mv, .current = ma, .ntc = ntc});
}

/* The current every tick; the supply, the power and the temperature each
 * in its own tick of a round, once a round. */
static void test_each_reading_in_its_turn(void **state)
{
    (void)state;
    struct sensor_filter f = {0};
    assert_int_equal(tick(&f, 7400, 800, 2000), SENSE_VOLTAGE); /* primes */
    unsigned voltage_turns = 0, power_turns = 0, temperature_turns = 0;
    for (unsigned i = 1; i <= 10 * SENSE_ROUND_TICKS; i++) {
        struct sensor_readings before = f.out;
        enum sense_slot slot = tick(&f, 6400, (uint16_t)(i % 2 ? 1200 : 400), 1000);
        assert_int_equal(slot, i % SENSE_ROUND_TICKS);
        assert_int_not_equal(f.out.current_ma, before.current_ma); /* moves every tick */
        voltage_turns += f.out.voltage_mv != before.voltage_mv;
        power_turns += f.out.power_mw != before.power_mw;
        temperature_turns += f.out.temperature_adc != before.temperature_adc;
        assert_true(f.out.voltage_mv == before.voltage_mv || slot == SENSE_VOLTAGE);
        assert_true(f.out.power_mw == before.power_mw || slot == SENSE_POWER);
        assert_true(f.out.temperature_adc == before.temperature_adc || slot == SENSE_TEMPERATURE);
    }
    assert_true(voltage_turns >= 8 && power_turns >= 8 && temperature_turns >= 8);
}

/* One noisy sample moves the current by an eighth of its jump and a slow
 * reading by a quarter; steady samples bring both back exactly. */
static void test_filter_tames_one_sample(void **state)
{
    (void)state;
    struct sensor_filter f = {0};
    tick(&f, 7400, 800, 2000); /* primes */
    assert_int_equal(f.out.voltage_mv, 7400);
    assert_int_equal(f.out.power_mw, 5920);
    for (unsigned i = 1; i < SENSE_ROUND_TICKS; i++) {
        tick(&f, 7400, 800, 2000);
    }
    tick(&f, 3400, 1600, 2000); /* the supply's turn: one sample 4 V low, 0.8 A high */
    assert_int_equal(f.out.voltage_mv, 6400); /* a quarter of the jump */
    assert_int_equal(f.out.current_ma, 900);  /* an eighth */
    for (unsigned i = 0; i < 100 * SENSE_ROUND_TICKS; i++) {
        tick(&f, 7400, 800, 2000);
    }
    assert_int_equal(f.out.voltage_mv, 7400); /* settles exactly */
    assert_int_equal(f.out.current_ma, 800);
    assert_int_equal(f.out.power_mw, 5920);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_falls_and_matches_the_formula),
        cmocka_unit_test(test_protocol_reference_points),
        cmocka_unit_test(test_scaling_to_units),
        cmocka_unit_test(test_power_is_the_product_to_within_a_milliwatt_an_ampere),
        cmocka_unit_test(test_each_reading_in_its_turn),
        cmocka_unit_test(test_filter_tames_one_sample),
    };
    return cmocka_run_group_tests_name("sensors", tests, NULL, NULL);
}
