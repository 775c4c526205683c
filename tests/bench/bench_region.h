/* A measured region of a benchmark: the ARM build runs under QEMU and an
 * instruction-counting TCG plugin counts the Thumb-2 instructions executed
 * between bench_begin() and bench_end() (bench_region_target.c,
 * tests/bench/target/). A name measured more than once is summed. */
#ifndef BENCH_REGION_H
#define BENCH_REGION_H

/* Once, before the first region. */
void bench_setup(void);
void bench_begin(void);
/* Ends the region and names it. */
void bench_end(const char *name);

#endif
