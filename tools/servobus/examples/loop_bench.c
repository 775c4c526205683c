/* The C robot loop as fast as the wire goes, for scripts/c_loop_bench.sh:
 *   sb_loop_bench HOST:PORT|/dev/PORT CLOCK_FILE BAUD COUNT CYCLES [paced]
 * (a path: a serial port, or servo_sim's pseudo-terminal)
 * prints "cycles C seconds S rate R wire W ratio Q missed M" on servo_sim's
 * clock (the simulated servos' time). paced: servo_sim runs --clock paced
 * and this is its only host; the host's own time then costs none (tests). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "servobus/servobus_posix.h"
#include "examples/sb_sim_clock.h"

/* A whole decimal number within least..most, or -1. */
static long whole(const char *s, long least, long most)
{
    char *end = NULL;
    long n;
    if (s[0] < '0' || s[0] > '9')
        return -1;
    n = strtol(s, &end, 10);
    return *end == '\0' && n >= least && n <= most ? n : -1;
}

int main(int argc, char **argv)
{
    sb_posix link;
    sb_bus bus;
    sb_loop loop;
    uint8_t ids[SB_MAX_SERVOS];
    int32_t angles[SB_MAX_SERVOS];
    sb_monitor_answer states[SB_MAX_SERVOS];
    bool got[SB_MAX_SERVOS];
    const char *where, *colon;
    char host[256]; /* HOST of HOST:PORT (argv stays as given, for the messages) */
    size_t count;
    long cycles;
    uint32_t baud;
    sb_error e;
    char words[256];
    sim_clock_status clock_status = SIM_CLOCK_OK;
    int paced = argc == 7 && strcmp(argv[6], "paced") == 0;
    if (argc != 6 && !paced) {
        fprintf(stderr, "usage: %s HOST:PORT|/dev/PORT CLOCK_FILE BAUD COUNT CYCLES [paced]\n", argv[0]);
        return 2;
    }
    where = argv[1];
    if (strncmp(where, "socket://", 9) == 0) /* as servo_sim and servoctl print it */
        where += 9;
    colon = where[0] == '/' ? NULL : strrchr(where, ':');
    baud = (uint32_t)(whole(argv[3], 1, 4000000) > 0 ? whole(argv[3], 1, 4000000) : 0);
    count = (size_t)(whole(argv[4], 1, SB_MAX_SERVOS) > 0 ? whole(argv[4], 1, SB_MAX_SERVOS) : 0);
    cycles = whole(argv[5], 1, 100000000);
    if (where[0] != '/' && colon == NULL) {
        fprintf(stderr, "loop_bench: '%s' is neither HOST:PORT nor a /dev path\n", argv[1]);
        return 2;
    }
    if (baud == 0) {
        fprintf(stderr, "loop_bench: BAUD '%s' is not a baud rate (a whole number, 1-4000000)\n", argv[3]);
        return 2;
    }
    if (count == 0 || count > SB_MAX_SERVOS || cycles < 1) {
        fprintf(stderr, "loop_bench: COUNT must be 1-%d servos and CYCLES at least 1\n", SB_MAX_SERVOS);
        return 2;
    }
    if (sim_clock_open(argv[2]) != 0) {
        fprintf(stderr, "loop_bench: the clock file %s %s\n", argv[2], sim_clock_why(sim_clock_last()));
        return 2;
    }
    if (colon != NULL && (size_t)(colon - where) >= sizeof host) {
        fprintf(stderr, "loop_bench: the host in '%s' is longer than %u characters\n", argv[1],
                (unsigned)sizeof host - 1u);
        return 2;
    }
    if (colon != NULL) {
        memcpy(host, where, (size_t)(colon - where));
        host[colon - where] = '\0';
    }
    int rc = colon != NULL ? sb_tcp_open(&link, host, (unsigned)atoi(colon + 1)) : sb_serial_open(&link, where, baud);
    if (rc != 0) {
        fprintf(stderr, rc == -EBUSY ? "loop_bench: another program holds the bus at %s: close it, then try again\n"
                                     : "loop_bench: no simulator at %s\n", argv[1]);
        return 2;
    }
    {
        sb_transport t = sb_posix_transport(&link);
        t.now_us = sim_clock_us;
        if (paced)
            t = sim_clock_paced(argv[2], t, &clock_status);
        if (clock_status != SIM_CLOCK_OK) {
            fprintf(stderr, "loop_bench: paced: the clock file %s %s\n", argv[2], sim_clock_why(clock_status));
            return 2;
        }
        sb_bus_init(&bus, t, baud);
    }
    for (size_t k = 0; k < count; k++)
        ids[k] = (uint8_t)(k + 1);
    /* The cycles go back to back, as fast as the wire and the host go: the
     * period given is the wire's own cycle (the shortest sb_loop_init
     * allows), the one a loop this fast keeps at best. */
    {
        uint64_t wire_ms = ((uint64_t)sb_cycle_bytes(count) * SB_BITS_PER_BYTE * 1000u + baud - 1u) / baud;
        e = sb_loop_init(&loop, &bus, ids, count, (uint16_t)(wire_ms < 65535u ? wire_ms : 65535u));
    }
    for (long c = 0; c < cycles && e.status == SB_OK; c++) {
        for (size_t k = 0; k < count; k++)
            angles[k] = (int32_t)lround(100.0 * sin((double)c / 20.0)); /* 10 deg, as stream_bench.sh's */
        e = sb_loop_cycle(&loop, angles, NULL, states, got);
        if (e.status == SB_E_NO_ANSWER)
            e = sb_ok(); /* counted in loop.missed */
    }
    if (e.status != SB_OK) {
        sb_error_text(&e, words, sizeof words);
        fprintf(stderr, "loop_bench: %s\n", words);
        return 1;
    }
    {
        double rate = sb_loop_rate_hz(&loop), wire = sb_wire_limit_hz(count, baud);
        if (rate <= 0.0) {
            fprintf(stderr, "loop_bench: the simulator's clock did not move over %lu cycles\n",
                    (unsigned long)loop.cycles);
            return 3;
        }
        printf("cycles %lu seconds %.4f rate %.1f wire %.1f ratio %.4f missed %lu\n", (unsigned long)loop.cycles,
               (double)loop.cycles / rate, rate, wire, rate / wire, (unsigned long)loop.missed);
    }
    sb_posix_close(&link);
    return 0;
}
