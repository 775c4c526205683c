#define _DEFAULT_SOURCE
#include <fcntl.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "servobus/servobus_posix.h"
#include "examples/sb_sim_clock.h"

/* The clock file (firmware/boards/host_sim/sim_clock.h): u64 words. */
enum { CLOCK_NOW, CLOCK_HOST_WAITS, CLOCK_HOST_SENT, CLOCK_HOST_READ, CLOCK_WORDS };
#define UNTIL_ANSWER (UINT64_C(1) << 63)
/* A paced wait looks at the clock this often, host time, for bytes that
 * come short of what it wants (a silent servo's). */
#define PACED_LOOK_US 1000u

static volatile uint64_t *clock_words;

static volatile uint64_t *map_clock(const char *path, int writable)
{
    int fd = open(path, writable ? O_RDWR : O_RDONLY);
    void *map;
    if (fd < 0)
        return NULL;
    map = mmap(NULL, (writable ? CLOCK_WORDS : 1) * sizeof(uint64_t), writable ? PROT_READ | PROT_WRITE : PROT_READ,
               MAP_SHARED, fd, 0);
    close(fd);
    return map == MAP_FAILED ? NULL : (volatile uint64_t *)map;
}

int sim_clock_open(const char *path)
{
    clock_words = map_clock(path, 0);
    return clock_words != NULL ? 0 : -1;
}

uint64_t sim_clock_us(void *ctx)
{
    if (clock_words == NULL)
        return sb_monotonic_us(ctx);
    for (;;) { /* twice alike: a copy that overlapped the simulator's store is read again */
        uint64_t first = clock_words[CLOCK_NOW];
        if (clock_words[CLOCK_NOW] == first)
            return first;
    }
}

/* One paced host a process: the examples run one bus. */
static struct paced {
    sb_transport inner;
    uint64_t sent, read, read_at_send;
} paced;

static int paced_write(void *ctx, const uint8_t *data, size_t len)
{
    int rc = paced.inner.write(ctx, data, len);
    if (rc >= 0) {
        /* After the write: the simulator takes the bytes when they were sent. */
        paced.sent += len;
        paced.read_at_send = paced.read;
        clock_words[CLOCK_HOST_SENT] = paced.sent;
    }
    return rc;
}

static int paced_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    uint64_t stop = sim_clock_us(NULL) + wait_us;
    int n;
    if (wait_us > 0) {
        /* The bus has looked at every byte it read and waits for more: told
         * only once bytes came since the host last sent (sim_clock.h). */
        if (paced.read > paced.read_at_send)
            clock_words[CLOCK_HOST_READ] = paced.read;
        clock_words[CLOCK_HOST_WAITS] = stop | UNTIL_ANSWER;
    }
    for (;;) {
        n = paced.inner.read(ctx, buf, cap, want, wait_us > 0 ? PACED_LOOK_US : 0u);
        if (n != 0 || wait_us == 0 || sim_clock_us(NULL) >= stop)
            break;
    }
    if (n > 0)
        paced.read += (uint64_t)n;
    return n;
}

sb_transport sim_clock_paced(const char *path, sb_transport inner, int *ok)
{
    sb_transport t = inner;
    volatile uint64_t *words = map_clock(path, 1);
    *ok = words != NULL && words[CLOCK_HOST_SENT] == 0 && words[CLOCK_HOST_READ] == 0;
    if (!*ok) {
        if (words != NULL)
            munmap((void *)(uintptr_t)words, CLOCK_WORDS * sizeof(uint64_t));
        return inner;
    }
    clock_words = words;
    memset(&paced, 0, sizeof paced);
    paced.inner = inner;
    t.write = paced_write;
    t.read = paced_read;
    t.now_us = sim_clock_us;
    return t;
}
