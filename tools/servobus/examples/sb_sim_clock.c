#define _DEFAULT_SOURCE
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "servobus/servobus_posix.h"
#include "examples/sb_sim_clock.h"

/* The clock file (firmware/boards/host_sim/sim_clock.h): u64 words. */
enum { CLOCK_NOW, CLOCK_HOST_WAITS, CLOCK_HOST_SENT, CLOCK_HOST_READ, CLOCK_WORDS };
#define UNTIL_ANSWER (UINT64_C(1) << 63)
/* A paced wait looks at the clock this often, host time, for bytes that
 * come short of what it wants (a silent servo's). */
#define PACED_LOOK_US 1000u

/* A clock that stands still this long on the PC's clock: stopped or gone
 * (servoctl's Simulator.clock_s gives up after as long); the environment's
 * SB_SIM_CLOCK_STALLED_S another number of seconds (tests). */
#define STALLED_S 30u

/* One paced host a process: the examples run one bus. */
static struct paced {
    sb_transport inner;
    uint64_t sent, read, read_at_send;
} paced;

static volatile uint64_t *clock_words;
static sim_clock_status last_status = SIM_CLOCK_NO_FILE;

const char *sim_clock_why(sim_clock_status status)
{
    static const char *const WHY[] = {
        "ok",
        "cannot be opened (a simulator's state folder holds it: STATE/bus.clock)",
        "is not a simulator's clock file (too short)",
        "belongs to a simulator another host has used: a paced host must be its first "
        "(start a fresh servo_sim --clock paced)",
    };
    return (unsigned)status < sizeof WHY / sizeof WHY[0] ? WHY[status] : "unknown";
}

static volatile uint64_t *map_clock(const char *path, int writable, sim_clock_status *status)
{
    size_t size = (writable ? CLOCK_WORDS : 1) * sizeof(uint64_t);
    struct stat st;
    void *map = MAP_FAILED;
    int fd = open(path, writable ? O_RDWR : O_RDONLY);
    *status = SIM_CLOCK_NO_FILE;
    if (fd < 0)
        return NULL;
    /* A mapping past the file's end faults when read (SIGBUS). */
    if (fstat(fd, &st) == 0 && (st.st_size < 0 || (size_t)st.st_size < size))
        *status = SIM_CLOCK_NOT_CLOCK;
    else
        map = mmap(NULL, size, writable ? PROT_READ | PROT_WRITE : PROT_READ, MAP_SHARED, fd, 0);
    close(fd);
    if (map == MAP_FAILED)
        return NULL;
    *status = SIM_CLOCK_OK;
    return (volatile uint64_t *)map;
}

int sim_clock_open(const char *path)
{
    clock_words = map_clock(path, 0, &last_status);
    return clock_words != NULL ? 0 : -1;
}

sim_clock_status sim_clock_last(void)
{
    return last_status;
}

static uint64_t stalled_s(void)
{
    static uint64_t s;
    if (s == 0) {
        const char *env = getenv("SB_SIM_CLOCK_STALLED_S");
        unsigned long n = env != NULL ? strtoul(env, NULL, 10) : 0u;
        s = n > 0 ? n : STALLED_S;
    }
    return s;
}

uint64_t sim_clock_us(void *ctx)
{
    static uint64_t seen = UINT64_MAX, seen_at;
    uint64_t now, pc;
    if (clock_words == NULL)
        return sb_monotonic_us(ctx);
    for (;;) { /* twice alike: a copy that overlapped the simulator's store is read again */
        now = clock_words[CLOCK_NOW];
        if (clock_words[CLOCK_NOW] == now)
            break;
    }
    pc = sb_monotonic_us(NULL);
    if (now != seen) {
        seen = now;
        seen_at = pc;
    } else if (pc - seen_at > stalled_s() * 1000000u) {
        fprintf(stderr, "servo_sim's clock stood still for %lu s: the simulator stopped, or %s\n",
                (unsigned long)stalled_s(),
                paced.inner.read != NULL ? "a host before this one did not pace it (a paced host must be its first)"
                                         : "it runs --clock paced and this program does not pace it");
        exit(3);
    }
    return now;
}

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
    /* The wait ends once the clock is past its end, the simulator stood
     * still a microsecond on: it publishes an event's time before it hands
     * the host that event's bytes, so a host that stopped at the end
     * itself could look before the last of them came (and a run missed
     * more or fewer answers by the PC's timing). */
    uint64_t stop = sim_clock_us(NULL) + wait_us;
    int n;
    if (wait_us > 0) {
        /* The bus has looked at every byte it read and waits for more: told
         * only once bytes came since the host last sent (sim_clock.h). */
        if (paced.read > paced.read_at_send)
            clock_words[CLOCK_HOST_READ] = paced.read;
        clock_words[CLOCK_HOST_WAITS] = (stop + 1u) | UNTIL_ANSWER;
    }
    for (;;) {
        n = paced.inner.read(ctx, buf, cap, want, wait_us > 0 ? PACED_LOOK_US : 0u);
        if (n != 0 || wait_us == 0 || sim_clock_us(NULL) > stop)
            break;
    }
    if (n > 0)
        paced.read += (uint64_t)n;
    return n;
}

sb_transport sim_clock_paced(const char *path, sb_transport inner, sim_clock_status *status)
{
    sb_transport t = inner;
    volatile uint64_t *words = map_clock(path, 1, status);
    if (words != NULL && (words[CLOCK_HOST_SENT] != 0 || words[CLOCK_HOST_READ] != 0))
        *status = SIM_CLOCK_USED;
    if (*status != SIM_CLOCK_OK) {
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
