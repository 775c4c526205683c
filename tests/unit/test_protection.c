/* The protection monitors driven with sequences of readings: every threshold
 * at, just below and just above its limit, debouncing, hysteresis, recovery,
 * both stall modes, several faults at once; the exact status bits (2-7) and
 * action after each step. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "sensors/ntc.h"
#include "protection/protection.h"
#include "registers/data_table.h"

static struct protection prot;
static struct user_config cfg;
static struct sensor_readings readings;
/* The stall monitor's inputs from the motion layer. */
static struct {
    int8_t output_at_limit;
    int32_t speed_q8;
    uint32_t motion_commands;
} in;
static unsigned ticks; /* since setup: the slot of the next sample */

static int setup(void **state)
{
    (void)state;
    protection_init(&prot);
    user_config_factory(&cfg);
    /* Healthy: 7.4 V, 0.5 A, 3.7 W, 25 degC, moving freely. */
    readings = (struct sensor_readings){
        .voltage_mv = 7400, .current_ma = 500, .power_mw = 3700, .temperature_adc = 2048};
    in.output_at_limit = 0;
    in.speed_q8 = 0;
    in.motion_commands = 0;
    ticks = 0;
    return 0;
}

/* n ticks of the current readings, each slow one judged in its turn, as
 * sensors_update hands them over; the status bits after the last. */
static uint8_t run(unsigned n)
{
    uint8_t bits = 0;
    for (unsigned i = 0; i < n; i++) {
        enum sense_slot slot = (enum sense_slot)(ticks++ % SENSE_ROUND_TICKS);
        uint8_t changes = prot.act_changes;
        uint8_t before_bits = prot.threshold_bits;
        uint16_t before_cap = prot.act.power_cap_mw;
        bits = (uint8_t)(protection_update(&prot, &cfg, &readings, slot) |
                         protection_stall(&prot, &cfg, in.output_at_limit, in.speed_q8,
                                          in.motion_commands));
        /* act_changes counts every change the output must follow. */
        bool changed = before_bits != prot.threshold_bits || before_cap != prot.act.power_cap_mw;
        assert_true(!changed || prot.act_changes != changes);
    }
    return bits;
}

/* Ticks until the status bits are want (at most 1000). */
static unsigned ticks_until(uint8_t want)
{
    for (unsigned n = 1; n <= 1000; n++) {
        if (run(1) == want) {
            return n;
        }
    }
    fail_msg("the status bits never became %#x", want);
    return 0;
}

/* A condition trips when it has lasted PROTECT_TRIP_TICKS (clears after
 * PROTECT_CLEAR_TICKS) in samples: exactly then for a monitor judged every
 * tick, within its last round for one judged once a round. */
static void assert_lasted(unsigned taken, unsigned ticks_wanted, unsigned period)
{
    assert_in_range(taken, ticks_wanted - period + 1u, ticks_wanted);
}

/* A threshold monitor, generically: value pointer, limit, the first value
 * that trips, a value inside the hysteresis band (does not clear), the first
 * value that clears, and the expected bit. */
static void check_threshold(uint16_t *value, uint16_t healthy, uint16_t at_limit_ok,
                            uint16_t trips, uint16_t in_band, uint16_t clears, uint8_t bit,
                            unsigned period)
{
    *value = at_limit_ok;
    assert_int_equal(run(1000), 0); /* at (or just inside) the limit: fine */
    for (unsigned phase = 0; phase < period; phase++) { /* wherever the round stands */
        run(phase);
        *value = trips;
        assert_lasted(ticks_until(bit), PROTECT_TRIP_TICKS, period);
        *value = in_band;
        assert_int_equal(run(1000), bit); /* inside the band: still set */
        *value = clears;
        assert_lasted(ticks_until(0), PROTECT_CLEAR_TICKS, period);
        *value = healthy;
        assert_int_equal(run(10), 0);
    }
}

static void test_low_voltage(void **state)
{
    (void)state;
    uint16_t *v = &readings.voltage_mv;
    check_threshold(v, 7400, 4000, 3999, 4199, 4200, STATUS_LOW_VOLTAGE, SENSE_ROUND_TICKS);
    *v = 3999;
    run(PROTECT_TRIP_TICKS);
    assert_true(protection_inhibits(prot.threshold_bits));
    assert_false(protection_derates(prot.threshold_bits));
}

static void test_high_voltage(void **state)
{
    (void)state;
    check_threshold(&readings.voltage_mv, 7400, 8400, 8401, 8201, 8200, STATUS_HIGH_VOLTAGE,
                    SENSE_ROUND_TICKS);
    readings.voltage_mv = 8401;
    run(PROTECT_TRIP_TICKS);
    assert_true(protection_inhibits(prot.threshold_bits));
}

static void test_over_current(void **state)
{
    (void)state;
    check_threshold(&readings.current_ma, 500, 4000, 4001, 3901, 3900, STATUS_OVER_CURRENT, 1);
    readings.current_ma = 4001;
    run(PROTECT_TRIP_TICKS);
    assert_true(protection_derates(prot.threshold_bits));
    assert_false(protection_inhibits(prot.threshold_bits));
}

static void test_over_power(void **state)
{
    (void)state;
    check_threshold(&readings.power_mw, 3700, 10000, 10001, 9501, 9500, STATUS_OVER_POWER,
                    SENSE_ROUND_TICKS);
    readings.power_mw = 10001;
    run(PROTECT_TRIP_TICKS);
    assert_true(protection_derates(prot.threshold_bits));
}

static void test_over_temperature_trips_at_or_below(void **state)
{
    (void)state;
    /* 41 = 651 (about 75.6 degC); the ADC falls as it heats, 651 itself
     * trips; clearing needs 5 degC cooler. */
    uint16_t cool = ntc_adc((int16_t)(ntc_decicelsius(651) - 50));
    assert_true(cool > 700 && cool < 800);
    check_threshold(&readings.temperature_adc, 2048, 652, 651, (uint16_t)(cool - 1), cool,
                    STATUS_OVER_TEMPERATURE, SENSE_ROUND_TICKS);
    readings.temperature_adc = 600;
    run(PROTECT_TRIP_TICKS);
    assert_true(protection_inhibits(prot.threshold_bits));
}

static void test_one_noisy_sample_neither_trips_nor_clears(void **state)
{
    (void)state;
    /* Spikes in one sample of the supply's (once a round), never two in a
     * row, and in the current, judged every tick, never 10 in a row. */
    for (unsigned i = 0; i < 100; i++) {
        readings.voltage_mv = (i % (2 * SENSE_ROUND_TICKS) == 0) ? 2000 : 7400;
        readings.current_ma = (i % PROTECT_TRIP_TICKS == 0) ? 5000 : 500;
        assert_int_equal(run(1), 0);
    }
    readings.voltage_mv = 2000;
    assert_int_equal(run(PROTECT_TRIP_TICKS), STATUS_LOW_VOLTAGE);
    for (int i = 0; i < 500; i++) {
        readings.voltage_mv = (i % 50 == 0) ? 7400 : 2000;
        assert_int_equal(run(1), STATUS_LOW_VOLTAGE);
    }
}

static void test_several_faults_at_once(void **state)
{
    (void)state;
    readings.voltage_mv = 3000;
    readings.current_ma = 5000;
    readings.temperature_adc = 500;
    assert_int_equal(run(PROTECT_TRIP_TICKS),
                     STATUS_LOW_VOLTAGE | STATUS_OVER_CURRENT | STATUS_OVER_TEMPERATURE);
    assert_int_equal(STATUS_LOW_VOLTAGE | STATUS_OVER_CURRENT | STATUS_OVER_TEMPERATURE, 0xB0);
    assert_true(protection_inhibits(prot.threshold_bits) && protection_derates(prot.threshold_bits));
    readings.voltage_mv = 7400; /* one clears, the others stay */
    assert_int_equal(run(PROTECT_CLEAR_TICKS), STATUS_OVER_CURRENT | STATUS_OVER_TEMPERATURE);
    assert_true(protection_inhibits(prot.threshold_bits)); /* still hot */
    readings.temperature_adc = 2048;
    readings.current_ma = 100;
    assert_int_equal(run(PROTECT_CLEAR_TICKS), 0);
    assert_false(protection_inhibits(prot.threshold_bits) || protection_derates(prot.threshold_bits));
}

static void test_limits_follow_the_user_area(void **state)
{
    (void)state;
    cfg.low_voltage_mv = 6000;
    readings.voltage_mv = 5999;
    assert_int_equal(run(PROTECT_TRIP_TICKS), STATUS_LOW_VOLTAGE);
}

/* Every monitor at both ends of its range: whatever the limit and the
 * (constant) reading, the bit changes at most once, and it is set exactly
 * when the reading is beyond the limit. A limit of 65535 used to wrap the
 * low-voltage clear level to 199 mV, and the bit flipped every 110 ms. */
static void test_no_monitor_flaps_at_the_ends_of_its_range(void **state)
{
    (void)state;
    struct {
        uint16_t *limit;
        uint16_t *value;
        uint8_t bit;
        int trips_above;
        int inclusive;
    } const rows[] = {
        {&cfg.low_voltage_mv, &readings.voltage_mv, STATUS_LOW_VOLTAGE, 0, 0},
        {&cfg.high_voltage_mv, &readings.voltage_mv, STATUS_HIGH_VOLTAGE, 1, 0},
        {&cfg.current_limit_ma, &readings.current_ma, STATUS_OVER_CURRENT, 1, 0},
        {&cfg.power_limit_mw, &readings.power_mw, STATUS_OVER_POWER, 1, 0},
        {&cfg.temperature_limit_adc, &readings.temperature_adc, STATUS_OVER_TEMPERATURE, 0, 1},
    };
    const uint16_t ends[] = {0, 1, 99, 100, 199, 200, 201, 4095, 65334, 65335, 65336, 65400, 65534, 65535};
    for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        for (size_t l = 0; l < sizeof ends / sizeof ends[0]; l++) {
            for (size_t v = 0; v < sizeof ends / sizeof ends[0]; v++) {
                setup(NULL);
                cfg.low_voltage_mv = 0; /* only the monitor under test can trip */
                cfg.high_voltage_mv = UINT16_MAX;
                cfg.current_limit_ma = UINT16_MAX;
                cfg.power_limit_mw = UINT16_MAX;
                cfg.temperature_limit_adc = 0;
                readings.temperature_adc = 4095;
                *rows[r].limit = ends[l];
                *rows[r].value = ends[v];
                uint16_t value = ends[v];
                uint16_t limit = ends[l];
                int beyond = rows[r].trips_above ? (rows[r].inclusive ? value >= limit : value > limit)
                                                 : (rows[r].inclusive ? value <= limit : value < limit);
                unsigned changes = 0;
                uint8_t last = 0;
                for (int i = 0; i < 1000; i++) {
                    uint8_t bits = run(1);
                    changes += (bits != last);
                    last = bits;
                }
                assert_true(changes <= 1);
                assert_int_equal(last, beyond ? rows[r].bit : 0);
            }
        }
    }
}

static void test_stall_limits_power_in_mode_0(void **state)
{
    (void)state;
    cfg.stall_release = 0;
    cfg.stall_power_mw = 2500;
    in.output_at_limit = 1;
    in.speed_q8 = STALL_SPEED_Q8 - 1; /* just below 5 deg/s */
    assert_int_equal(run(STALL_TICKS - 1), 0);
    assert_int_equal(prot.act.power_cap_mw, 0);
    assert_int_equal(run(1), STATUS_STALL);
    assert_int_equal(prot.act.power_cap_mw, 2500);
    assert_false(prot.act.release_now);
    /* Still pushing at the (now lower) limit: stays. */
    assert_int_equal(run(1000), STATUS_STALL);
    /* It moves again: clears after the clear time. */
    in.speed_q8 = STALL_SPEED_Q8; /* at the speed limit, the way it pushes */
    assert_int_equal(run(PROTECT_CLEAR_TICKS - 1), STATUS_STALL);
    assert_int_equal(run(1), 0);
    assert_int_equal(prot.act.power_cap_mw, 0);
}

static void test_no_stall_while_moving_or_not_pushing(void **state)
{
    (void)state;
    in.output_at_limit = 1;
    in.speed_q8 = STALL_SPEED_Q8; /* 5 deg/s: moving */
    assert_int_equal(run(3 * STALL_TICKS), 0);
    in.output_at_limit = 0;
    in.speed_q8 = 0; /* still, but not pushing hard */
    assert_int_equal(run(3 * STALL_TICKS), 0);
}

/* A load stronger than the motor turns the horn backwards while the output
 * pushes forwards at its limit: that is a stall too, either way round. */
static void test_pushed_backwards_at_the_limit_is_a_stall(void **state)
{
    (void)state;
    cfg.stall_release = 0;
    in.output_at_limit = 1;
    in.speed_q8 = -40 * STALL_SPEED_Q8; /* 200 deg/s the wrong way */
    assert_int_equal(run(STALL_TICKS - 1), 0);
    assert_int_equal(run(1), STATUS_STALL);
    setup(NULL);
    in.output_at_limit = -1;
    in.speed_q8 = STALL_SPEED_Q8;
    assert_int_equal(run(STALL_TICKS), STATUS_STALL);
    setup(NULL);
    in.output_at_limit = -1; /* at the limit, moving the way it pushes */
    in.speed_q8 = -STALL_SPEED_Q8;
    assert_int_equal(run(3 * STALL_TICKS), 0);
}

/* Settings changed while a stall is set reach the output: a new stall power
 * (38) while capped, and release mode (37) switched on mid-stall, which
 * shows only a stall it latched itself. */
static void test_stall_settings_change_mid_stall(void **state)
{
    (void)state;
    cfg.stall_release = 0;
    cfg.stall_power_mw = 2500;
    in.output_at_limit = 1;
    in.speed_q8 = 0;
    assert_int_equal(run(STALL_TICKS), STATUS_STALL);
    assert_int_equal(prot.act.power_cap_mw, 2500);
    uint8_t changes = prot.act_changes;
    cfg.stall_power_mw = 1500;
    assert_int_equal(run(1), STATUS_STALL);
    assert_int_equal(prot.act.power_cap_mw, 1500);
    assert_int_not_equal(prot.act_changes, changes);
    cfg.stall_release = 1;
    assert_int_equal(run(1), 0);
    assert_int_equal(prot.act.power_cap_mw, 0);
    assert_false(prot.act.release_now);
}

static void test_stall_releases_in_mode_1(void **state)
{
    (void)state;
    cfg.stall_release = 1;
    in.output_at_limit = 1;
    in.motion_commands = 7;
    assert_int_equal(run(STALL_TICKS), STATUS_STALL);
    assert_true(prot.act.release_now); /* once */
    in.output_at_limit = 0;    /* released: nothing pushes */
    assert_int_equal(run(1), STATUS_STALL);
    assert_false(prot.act.release_now);
    assert_int_equal(run(5000), STATUS_STALL); /* held until a new command */
    in.motion_commands = 8;
    assert_int_equal(run(1), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_low_voltage, setup),
        cmocka_unit_test_setup(test_high_voltage, setup),
        cmocka_unit_test_setup(test_over_current, setup),
        cmocka_unit_test_setup(test_over_power, setup),
        cmocka_unit_test_setup(test_over_temperature_trips_at_or_below, setup),
        cmocka_unit_test_setup(test_one_noisy_sample_neither_trips_nor_clears, setup),
        cmocka_unit_test_setup(test_several_faults_at_once, setup),
        cmocka_unit_test_setup(test_limits_follow_the_user_area, setup),
        cmocka_unit_test_setup(test_no_monitor_flaps_at_the_ends_of_its_range, setup),
        cmocka_unit_test_setup(test_stall_limits_power_in_mode_0, setup),
        cmocka_unit_test_setup(test_no_stall_while_moving_or_not_pushing, setup),
        cmocka_unit_test_setup(test_pushed_backwards_at_the_limit_is_a_stall, setup),
        cmocka_unit_test_setup(test_stall_settings_change_mid_stall, setup),
        cmocka_unit_test_setup(test_stall_releases_in_mode_1, setup),
    };
    return cmocka_run_group_tests_name("protection", tests, NULL, NULL);
}
