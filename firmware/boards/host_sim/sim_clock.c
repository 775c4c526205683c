#define _GNU_SOURCE /* ftruncate, mmap under -std=c11 */

#include "sim_clock.h"

#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <sys/mman.h>
#include <unistd.h>

static _Atomic uint64_t *published;

bool sim_clock_open(const char *state_dir, char *path, unsigned path_size)
{
    snprintf(path, path_size, "%s/%s", state_dir, SIM_CLOCK_FILE);
    int fd = open(path, O_RDWR | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) {
        return false;
    }
    void *map = MAP_FAILED;
    if (ftruncate(fd, (off_t)(4 * sizeof(uint64_t))) == 0) {
        map = mmap(NULL, 4 * sizeof(uint64_t), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    }
    close(fd); /* the mapping keeps the file */
    if (map == MAP_FAILED) {
        return false;
    }
    published = map;
    return true;
}

void sim_clock_publish(uint64_t now_us)
{
    /* One aligned 8-byte store (x86-64, AArch64): a reader sees the old
     * clock or the new, never half of each. */
    if (published != NULL) {
        atomic_store_explicit(published, now_us, memory_order_release);
    }
}

uint64_t sim_clock_host_waits(void)
{
    return published != NULL ? atomic_load_explicit(&published[1], memory_order_acquire) : 0u;
}

uint64_t sim_clock_host_sent(void)
{
    return published != NULL ? atomic_load_explicit(&published[2], memory_order_acquire) : 0u;
}

uint64_t sim_clock_host_received(void)
{
    return published != NULL ? atomic_load_explicit(&published[3], memory_order_acquire) : 0u;
}
