/* The oscillation monitor's detector (motion_runs_away, motion/drive.c) and
 * the drive items' own check (drive_items_stable, motion/controller.c),
 * alone. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "motion/controller.h"
#include "motion/motion.h"
#include "registers/data_table.h"

enum {
    OFF_Q8 = RUNAWAY_AMPLITUDE_Q8 + 256, /* 10.1 deg */
    FAST_Q8 = 256,                       /* 100 deg/s */
    KV = 9903,                           /* the reference's, 7.4 V */
    BAND = 16400,                        /* 10 W's duty band */
};

static struct motion m;

static int setup(void **state)
{
    (void)state;
    m = (struct motion){.mode = MODE_POSITION};
    m.drive.kv = KV;
    m.drive.duty_limit = BAND;
    return 0;
}

/* n ticks of the same error (setpoint - horn), speed and limit; how many
 * tripped. */
static int ticks(int n, int32_t e, int32_t w, int8_t at_limit)
{
    m.setpoint_q8 = 0;
    m.measured_q8 = -e;
    m.measured_velocity_q8 = w;
    m.controller.at_limit = at_limit;
    int trips = 0;
    for (int i = 0; i < n; i++) {
        trips += motion_runs_away(&m, 300);
    }
    return trips;
}

/* Running away beyond the amplitude: trips on the 300th tick, either way. */
static void test_a_runaway_trips_at_the_items_time(void **state)
{
    (void)state;
    assert_int_equal(ticks(299, -OFF_Q8, FAST_Q8, 0), 0);
    assert_int_equal(ticks(1, -OFF_Q8, FAST_Q8, 0), 1);
    setup(NULL);
    assert_int_equal(ticks(299, OFF_Q8, -FAST_Q8, 0), 0);
    assert_int_equal(ticks(1, OFF_Q8, -FAST_Q8, 0), 1);
}

/* Coming back, creeping (the stall's speed), within the amplitude, or
 * released: not counted. */
static void test_coming_back_creeping_near_or_released_is_not_counted(void **state)
{
    (void)state;
    assert_int_equal(ticks(1000, -OFF_Q8, -FAST_Q8, 0), 0);            /* coming back */
    assert_int_equal(ticks(1000, -OFF_Q8, RUNAWAY_CREEP_Q8, 0), 0);     /* creeping */
    assert_int_equal(ticks(1000, RUNAWAY_AMPLITUDE_Q8, -FAST_Q8, 0), 0); /* at 10 deg */
    assert_int_equal(m.runaway_ticks, 0);
    assert_int_equal(ticks(200, -OFF_Q8, FAST_Q8, 0), 0);
    assert_int_equal(m.runaway_ticks, 400);
    m.mode = MODE_RELEASED;
    assert_int_equal(ticks(1000, -OFF_Q8, FAST_Q8, 0), 0);
    assert_int_equal(m.runaway_ticks, 0);
}

/* A swing: its outward parts add up, its time within the amplitude takes
 * half as much off. */
static void test_a_swing_adds_up_and_a_rest_takes_off(void **state)
{
    (void)state;
    int trips = 0;
    for (int half = 0; half < 5; half++) { /* 5 x 50 ms out, 50 back, 40 near */
        int32_t side = half % 2 ? 1 : -1;
        trips += ticks(50, side * OFF_Q8, -side * FAST_Q8, 0);
        trips += ticks(50, side * OFF_Q8, side * FAST_Q8, 0);
        trips += ticks(40, 0, side * FAST_Q8, 0);
    }
    assert_int_equal(trips, 0);
    assert_int_equal(m.runaway_ticks, 5 * (100 - 40));
    assert_int_equal(ticks(300 - 150, OFF_Q8, -FAST_Q8, 0), 1); /* 600 = 2 x 300 */
    m.runaway_ticks = 500;
    assert_int_equal(ticks(600, 0, 0, 0), 0);
    assert_int_equal(m.runaway_ticks, 0);
}

/* The output pushing back at its limit while a stronger load turns the horn
 * back slower than the band's speed: the stall monitor's. Faster, the limit
 * drives the horn the way it runs: counted. */
static void test_a_stronger_load_is_the_stall_monitors(void **state)
{
    (void)state;
    int32_t band_speed_q8 = (BAND << 8) / KV; /* 1.66 decideg per tick */
    /* kv to 1/256 (kv >> 8): the band's speed to 3 % on the reference */
    assert_int_equal(ticks(1000, -OFF_Q8, band_speed_q8 - 2, -1), 0);
    assert_int_equal(ticks(300, -OFF_Q8, band_speed_q8 + band_speed_q8 / 32, -1), 1);
}

static void factory(struct user_config *dt)
{
    user_config_factory(dt);
    assert_true(drive_items_stable(dt));
}

/* Mistyped drive items: each refused; the factory items,
 * a reversed ratio and ratio 0 (no plant declared) are not. */
static void test_mistyped_drive_items_are_unstable(void **state)
{
    (void)state;
    struct user_config dt;
    static const struct {
        uint8_t item;
        int32_t value;
    } typos[] = {{81, 37140}, {82, 3450}, {82, 32767}, {81, 65535}, {82, -3450}, {87, 1023}, {83, 1}};
    for (size_t i = 0; i < sizeof typos / sizeof typos[0]; i++) {
        factory(&dt);
        if (typos[i].item == 81) {
            dt.kt_un_m_per_a = (uint16_t)typos[i].value;
        } else if (typos[i].item == 82) {
            dt.gear_ratio = (int16_t)typos[i].value;
        } else if (typos[i].item == 83) {
            dt.inertia_mg_cm2 = (uint16_t)typos[i].value;
        } else {
            dt.gain_ki = (uint16_t)typos[i].value;
        }
        assert_false(drive_items_stable(&dt));
    }
    factory(&dt);
    dt.gear_ratio = -345;
    assert_true(drive_items_stable(&dt));
    dt.gear_ratio = 0;
    dt.gain_ki = 1023;
    assert_true(drive_items_stable(&dt));
}

/* The shipped plants' drive items (hal/ports/host/plants, as servoctl tune
 * writes them for 8 Hz) pass. */
static void test_the_shipped_plants_pass(void **state)
{
    (void)state;
    static const uint16_t plants[][9] = {
        /* R mOhm, kt, ratio, J mg cm^2, Coulomb, viscous, kp, ki, kd */
        {2741, 3714, 345, 1000, 2786, 1481, 497, 6, 3654},
        {6400, 1324, 300, 51, 662, 211, 223, 3, 1104},
        {2400, 5063, 387, 12570, 6330, 2811, 533, 3, 24297},
    };
    for (size_t i = 0; i < sizeof plants / sizeof plants[0]; i++) {
        struct user_config dt;
        user_config_factory(&dt);
        dt.resistance_mohm = plants[i][0];
        dt.kt_un_m_per_a = plants[i][1];
        dt.gear_ratio = (int16_t)plants[i][2];
        dt.inertia_mg_cm2 = plants[i][3];
        dt.coulomb_dun_m = plants[i][4];
        dt.viscous_100pn_m_s = plants[i][5];
        dt.gain_kp = plants[i][6];
        dt.gain_ki = plants[i][7];
        dt.gain_kd = plants[i][8];
        assert_true(drive_items_stable(&dt));
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_a_runaway_trips_at_the_items_time, setup),
        cmocka_unit_test_setup(test_coming_back_creeping_near_or_released_is_not_counted, setup),
        cmocka_unit_test_setup(test_a_swing_adds_up_and_a_rest_takes_off, setup),
        cmocka_unit_test_setup(test_a_stronger_load_is_the_stall_monitors, setup),
        cmocka_unit_test(test_mistyped_drive_items_are_unstable),
        cmocka_unit_test(test_the_shipped_plants_pass),
    };
    return cmocka_run_group_tests_name("oscillation", tests, NULL, NULL);
}
