#include "bench_region.h"

#include <valgrind/callgrind.h>

void bench_setup(void)
{
    CALLGRIND_ZERO_STATS;
}

void bench_begin(void)
{
    CALLGRIND_TOGGLE_COLLECT;
}

void bench_end(const char *name)
{
    CALLGRIND_TOGGLE_COLLECT;
    CALLGRIND_DUMP_STATS_AT(name);
}
