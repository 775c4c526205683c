/* servo_sim's USB-serial adapter model (sim_usb.c) against the fixed byte
 * timelines of sim_usb_timelines.txt, which the virtual boards' model
 * (tools/vboard/usb.py) must hand over the same way: 1 ms frames, the
 * 64-byte packet, the FTDI latency timer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "boards/host_sim/sim_usb.h"

#define MAX_BYTES 512u

/* "A" or "A+SxN" into times; their count. */
static unsigned parse_times(char *word, uint64_t *t, unsigned n)
{
    unsigned long long a = 0, s = 0, count = 1;
    if (sscanf(word, "%llu+%llux%llu", &a, &s, &count) < 3) {
        count = 1;
    }
    for (unsigned long long i = 0; i < count && n < MAX_BYTES; i++) {
        t[n++] = a + s * i;
    }
    return n;
}

/* The hand-overs of one timeline, as "us:bytes ...". */
static void run(const char *mode, uint32_t baud, const uint64_t *t, unsigned n, char *got, size_t cap)
{
    static struct sim_usb u;
    static uint8_t out[SIM_USB_HELD];
    assert_true(sim_usb_parse(mode, &u));
    got[0] = '\0';
    unsigned i = 0;
    for (unsigned steps = 0; steps < 10000u; steps++) {
        uint64_t due = sim_usb_due(&u);
        if (i < n && t[i] <= due) {
            sim_usb_hold(&u, (uint8_t)i, t[i], baud);
            i++;
            continue;
        }
        if (due == SIM_USB_NONE) {
            return;
        }
        unsigned k = sim_usb_take(&u, due, out, sizeof out);
        size_t len = strlen(got);
        snprintf(got + len, cap - len, "%s%llu:%u", len ? " " : "", (unsigned long long)due, k);
    }
    fail_msg("%s: no end of hand-overs", mode);
}

static void test_the_timelines(void **state)
{
    (void)state;
    FILE *f = fopen(SIM_USB_TIMELINES, "r");
    assert_non_null(f);
    char line[1024];
    unsigned cases = 0;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n') {
            continue;
        }
        char *want = strchr(line, '=');
        assert_non_null(want);
        *want++ = '\0';
        want += strspn(want, " ");
        want[strcspn(want, "\n")] = '\0';
        char *mode = strtok(line, " ");
        uint32_t baud = (uint32_t)strtoul(strtok(NULL, " "), NULL, 10);
        static uint64_t t[MAX_BYTES];
        unsigned n = 0;
        for (char *w = strtok(NULL, " "); w; w = strtok(NULL, " ")) {
            n = parse_times(w, t, n);
        }
        char got[1024];
        run(mode, baud, t, n, got, sizeof got);
        if (strcmp(got, want) != 0) {
            fail_msg("%s %u: handed over %s, not %s", mode, baud, got, want);
        }
        cases++;
    }
    fclose(f);
    assert_true(cases >= 8u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_the_timelines),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
