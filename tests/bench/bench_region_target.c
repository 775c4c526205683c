/* The plugin (qemu_insn_count.c) is told the addresses of the two marker
 * functions; it snapshots its instruction counter when each runs. The
 * region's name goes out over semihosting after the count has stopped. */
#include "bench/bench_region.h"

#include <stdint.h>
#include <stdio.h>

void bench_marker_begin(void);
void bench_marker_end(void);

__attribute__((noinline)) void bench_marker_begin(void)
{
    __asm__ volatile("" ::: "memory");
}

__attribute__((noinline)) void bench_marker_end(void)
{
    __asm__ volatile("" ::: "memory");
}

/* A loop whose count is known: 2 instructions an iteration (Thumb-1, so
 * the Cortex-M0 runs it too). The runner checks that 200 iterations count
 * exactly 200 instructions more than 100 do, before it trusts the plugin. */
__attribute__((noinline)) static void known_loop(uint32_t iterations)
{
    __asm__ volatile(".syntax unified\n"
                     "1: subs %0, #1\n"
                     "bne 1b\n"
                     : "+l"(iterations)
                     :
                     : "cc");
}

/* One function for both, so the code around the loop is the same. */
__attribute__((noinline)) static void measure_loop(uint32_t iterations, const char *name)
{
    bench_begin();
    known_loop(iterations);
    bench_end(name);
}

void bench_setup(void)
{
    /* A region with nothing in it: the markers' own cost, which the runner
     * takes off every other region. */
    bench_begin();
    bench_end("overhead");
    measure_loop(100, "calibration_100");
    measure_loop(200, "calibration_200");
}

void bench_begin(void)
{
    bench_marker_begin();
}

void bench_end(const char *name)
{
    bench_marker_end();
    printf("region %s\n", name);
}
