/* servobus's transports on a POSIX host (docs/c-library.md): a serial port
 * (termios; the driver's low-latency mode; a USB-serial adapter's latency
 * timer checked) and a TCP socket (servo_sim, the virtual boards). The
 * bus clock is CLOCK_MONOTONIC unless now_us is replaced. */
#ifndef SERVOBUS_POSIX_H
#define SERVOBUS_POSIX_H

#include "servobus/servobus.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sb_posix {
    int fd;
    bool is_socket;
    int low_water;       /* the socket's SO_RCVLOWAT now */
    bool low_latency;    /* the serial driver took ASYNC_LOW_LATENCY */
    int latency_timer_ms; /* the adapter's latency timer (sysfs), -1: none found */
    char advice[256];    /* what to do about a slow latency timer, or "" */
    /* A wait for bytes first looks this long without sleeping (0: sleeps
     * at once): bytes due soon are taken as they come, without the
     * process's wake-up. Opened: SB_POSIX_SPIN_US, 1.5 ms, longer than a
     * 6-servo robot loop's request takes on the wire at 1 Mbaud (760 us):
     * a sleeping host's wake-up has tails of up to 1 ms on a busy or
     * virtual PC (docs/c-library.md). A CPU's time for it. */
    uint32_t spin_us;
} sb_posix;

#define SB_POSIX_SPIN_US 1500u

/* A TCP connection to host:port (TCP_NODELAY). 0, or -errno (-EINVAL for a
 * port outside 1..65535, which getaddrinfo would take modulo 65536; -EBUSY
 * where a simulator says at once that another client holds its bus). */
int sb_tcp_open(sb_posix *p, const char *host, unsigned port);
/* A serial port at baud, 8N1 raw, low latency where the driver has it,
 * the adapter's latency timer read (and set to 1 ms where it may be;
 * otherwise advice names the fix). 0, or -errno (-EINVAL: a rate termios
 * does not have). */
int sb_serial_open(sb_posix *p, const char *path, uint32_t baud);
/* The latency timer of a USB-serial adapter behind path (e.g. ttyUSB0),
 * in ms, from /sys/class/tty/NAME/device/latency_timer; -1 if it has none. */
int sb_serial_latency_timer(const char *path);
/* What sb_serial_open does about it: above 1 ms, sets it to 1 where the
 * process may (latency_timer_ms then says 1), else fills advice with the
 * fix. ($SERVOBUS_SYSFS, if set, stands for /sys: the tests'.) */
void sb_serial_check_latency(sb_posix *p, const char *path);
void sb_posix_close(sb_posix *p);
sb_transport sb_posix_transport(sb_posix *p);
uint64_t sb_monotonic_us(void *ctx);

#ifdef __cplusplus
}
#endif

#endif
