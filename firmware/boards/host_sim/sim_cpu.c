#include "sim_cpu.h"

#include <stddef.h>
#include <string.h>

/* The target bench's modelled cycles (tests/bench/target/run_target_bench.py,
 * docs/benchmark.md: idle_poll, servo_tick_worst, the longest answer
 * that programs no flash: ReadStore on the M3, ReadMotion on the M0, and
 * sync_first_pass, up to the answer's start, less idle_poll) at
 * the boards' clocks, 72 MHz (STM32F103) and 48 MHz (STM32F030). A durable
 * write's flash time is the flash model's (sim_flash.h); its CPU share
 * beyond an answer's is not modelled. tick_and_pass_us: the boards'
 * BOARD_TICK_AND_PASS_US (stm32f103/board.h, stm32f030k6/board.h). */
static const struct sim_cpu cpus[] = {
    {.name = "m3", .pass_ns = 261 * 1000 / 72 + 1, .tick_ns = 989 * 1000 / 72 + 1,
     .answer_ns = 1153 * 1000 / 72 + 1, .sync_answer_ns = 721 * 1000 / 72 + 1, .tick_and_pass_us = 18},
    {.name = "m0", .pass_ns = 284 * 1000 / 48 + 1, .tick_ns = 1881 * 1000 / 48 + 1,
     .answer_ns = 1439 * 1000 / 48 + 1, .sync_answer_ns = 287 * 1000 / 48 + 1, .sends_ahead = true,
     .tick_and_pass_us = 48},
};

const struct sim_cpu *sim_cpu_named(const char *name)
{
    for (size_t i = 0; i < sizeof cpus / sizeof cpus[0]; i++) {
        if (strcmp(cpus[i].name, name) == 0) {
            return &cpus[i];
        }
    }
    return NULL;
}
