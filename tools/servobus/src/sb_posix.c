/* servobus's POSIX transports: a TCP socket and a serial port. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>
#ifdef __linux__
#include <linux/serial.h>
#endif

#include "servobus/servobus_posix.h"

/* The most bytes a wait on a socket asks for before it wakes (SO_RCVLOWAT).
 * A simulator sends each byte as it ends on the wire, a TCP segment each:
 * asked for more than its first congestion window (ten segments) holds,
 * a wait for a whole round stalls until its time-out in a connection's
 * first cycles (scripts/c_loop_bench.sh measured 5 ms a cycle at 21 or
 * more, none at 10). */
#define LOW_WATER_MOST 8u

uint64_t sb_monotonic_us(void *ctx)
{
    struct timespec ts;
    (void)ctx;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

static void reset(sb_posix *p)
{
    memset(p, 0, sizeof *p);
    p->fd = -1;
    p->low_water = 1;
    p->latency_timer_ms = -1;
    p->spin_us = SB_POSIX_SPIN_US;
}

/* What servo_sim and the virtual boards send a second client on their bus
 * (and then nothing): "<who>: the bus is in use by another client". */
#define BUS_IN_USE "the bus is in use by another client"

static bool holds(const uint8_t *buf, size_t n, const char *text)
{
    size_t len = strlen(text);
    for (size_t k = 0; k + len <= n; k++)
        if (memcmp(buf + k, text, len) == 0)
            return true;
    return false;
}

/* A simulator tells a second client at once that its bus is another's,
 * and then takes none of its bytes: a program that only sends (a move, a
 * stream) would otherwise believe them sent. Looked for (not read) for up
 * to OPEN_LOOK_MS after connecting; a bus that is free says nothing. */
#define OPEN_LOOK_MS 50

static bool held_by_another(sb_posix *p)
{
    struct pollfd pf = {p->fd, POLLIN, 0};
    uint8_t peek[96];
    if (poll(&pf, 1, OPEN_LOOK_MS) <= 0 || !(pf.revents & POLLIN))
        return false;
    ssize_t n = recv(p->fd, peek, sizeof peek, MSG_PEEK);
    if (n <= 0 || !holds(peek, (size_t)n, BUS_IN_USE))
        return false;
    close(p->fd);
    p->fd = -1;
    return true;
}

int sb_tcp_open(sb_posix *p, const char *host, unsigned port)
{
    struct addrinfo hints, *res = NULL, *a;
    char service[8];
    int one = 1, rc;
    reset(p);
    if (port == 0 || port > 65535u)
        return -EINVAL; /* getaddrinfo would take 109223 as 43687 */
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    snprintf(service, sizeof service, "%u", port);
    rc = getaddrinfo(host, service, &hints, &res);
    if (rc != 0)
        return -EHOSTUNREACH;
    rc = -ECONNREFUSED;
    for (a = res; a != NULL; a = a->ai_next) {
        int fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (fd < 0)
            continue;
        if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
            p->fd = fd;
            rc = 0;
            break;
        }
        rc = -errno;
        close(fd);
    }
    freeaddrinfo(res);
    if (rc != 0)
        return rc;
    p->is_socket = true;
    setsockopt(p->fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one); /* no Nagle delay on small frames */
    return held_by_another(p) ? -EBUSY : 0;
}

static speed_t speed_of(uint32_t baud)
{
    switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
#ifdef B500000
    case 500000: return B500000;
#endif
#ifdef B1000000
    case 1000000: return B1000000;
#endif
    default: return 0;
    }
}

/* How much of a device's name the latency advice shows. */
#define NAME_SHOWN 24

/* A port's device name (NAME of /dev/NAME) into name (NAME_MAX + 1 bytes),
 * its links resolved first: /dev/serial/by-id/usb-FTDI_...-port0 is ttyUSB0. */
static void port_name(const char *path, char *name)
{
    char real[PATH_MAX];
    const char *base;
    size_t n;
    if (realpath(path, real) != NULL)
        path = real;
    base = strrchr(path, '/');
    base = base != NULL ? base + 1 : path;
    n = strlen(base) < NAME_MAX ? strlen(base) : NAME_MAX;
    memcpy(name, base, n);
    name[n] = '\0';
}

/* The adapter's latency-timer file for a port's path, under
 * $SERVOBUS_SYSFS if set (the tests'), else /sys. */
static void timer_file(const char *path, char *out, size_t cap)
{
    char name[NAME_MAX + 1];
    const char *root = getenv("SERVOBUS_SYSFS");
    port_name(path, name);
    snprintf(out, cap, "%s/class/tty/%s/device/latency_timer", root != NULL ? root : "/sys", name);
}

int sb_serial_latency_timer(const char *path)
{
    char sys[256 + NAME_MAX];
    FILE *f;
    int ms = -1;
    timer_file(path, sys, sizeof sys);
    f = fopen(sys, "r");
    if (f == NULL)
        return -1;
    if (fscanf(f, "%d", &ms) != 1)
        ms = -1;
    fclose(f);
    return ms;
}

/* An FTDI adapter holds what it received until its latency timer runs out
 * (16 ms by default): at 1 ms a robot loop gets its answers a frame late,
 * at 16 ms it crawls. */
void sb_serial_check_latency(sb_posix *p, const char *path)
{
    char name[NAME_MAX + 1], sys[256 + NAME_MAX];
    FILE *f;
    int cut;
    port_name(path, name);
    p->advice[0] = '\0';
    p->latency_timer_ms = sb_serial_latency_timer(path);
    if (p->latency_timer_ms <= 1)
        return;
    timer_file(path, sys, sizeof sys);
    f = fopen(sys, "w");
    if (f != NULL) {
        bool written = fputs("1\n", f) >= 0;
        written = fclose(f) == 0 && written;
        p->latency_timer_ms = sb_serial_latency_timer(path);
        if (written && p->latency_timer_ms <= 1)
            return;
    }
    /* A USB serial device's name (ttyUSB0) is short; a longer one is shown
     * cut at NAME_SHOWN, so the advice always fits its buffer whole. */
    cut = snprintf(p->advice, sizeof p->advice,
                   "%.*s's latency timer is %d ms: every answer waits for it. Run "
                   "'echo 1 | sudo tee /sys/bus/usb-serial/devices/%.*s/latency_timer' "
                   "(or a udev rule setting ATTR{latency_timer}=\"1\")", NAME_SHOWN, name,
                   p->latency_timer_ms, NAME_SHOWN, name);
    (void)cut;
}

int sb_serial_open(sb_posix *p, const char *path, uint32_t baud)
{
    struct termios tio;
    speed_t speed = speed_of(baud);
    reset(p);
    if (speed == 0)
        return -EINVAL;
    p->fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (p->fd < 0)
        return -errno;
    /* One program on a bus: the lock servoctl (pyserial's exclusive) takes too. */
    if (flock(p->fd, LOCK_EX | LOCK_NB) != 0) {
        int rc = errno == EWOULDBLOCK ? -EBUSY : -errno;
        sb_posix_close(p);
        return rc;
    }
    if (tcgetattr(p->fd, &tio) != 0) {
        int rc = -errno;
        sb_posix_close(p);
        return rc;
    }
    cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~(tcflag_t)(CSTOPB | PARENB | CRTSCTS);
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    cfsetispeed(&tio, speed);
    cfsetospeed(&tio, speed);
    if (tcsetattr(p->fd, TCSANOW, &tio) != 0) {
        int rc = -errno;
        sb_posix_close(p);
        return rc;
    }
#ifdef ASYNC_LOW_LATENCY
    {
        struct serial_struct ss;
        if (ioctl(p->fd, TIOCGSERIAL, &ss) == 0) {
            ss.flags = (int)((unsigned)ss.flags | (unsigned)ASYNC_LOW_LATENCY);
            p->low_latency = ioctl(p->fd, TIOCSSERIAL, &ss) == 0;
        }
    }
#endif
    tcflush(p->fd, TCIOFLUSH);
    sb_serial_check_latency(p, path);
    return 0;
}

void sb_posix_close(sb_posix *p)
{
    if (p->fd >= 0)
        close(p->fd);
    p->fd = -1;
}

/* A link that takes no byte this long fails the write (a wedged adapter, a
 * peer that stopped reading), rather than hanging the program's loop. */
#define WRITE_STALL_MS 1000

static int posix_write(void *ctx, const uint8_t *data, size_t len)
{
    sb_posix *p = (sb_posix *)ctx;
    int stalled_ms = 0;
    while (len > 0) {
        ssize_t n = p->is_socket ? send(p->fd, data, len, MSG_NOSIGNAL | MSG_DONTWAIT) : write(p->fd, data, len);
        if (n < 0) {
            struct pollfd pf = {p->fd, POLLOUT, 0};
            if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
                return -errno;
            if (errno != EINTR && poll(&pf, 1, 100) == 0 && (stalled_ms += 100) >= WRITE_STALL_MS)
                return -ETIMEDOUT;
            continue;
        }
        stalled_ms = 0;
        data += n;
        len -= (size_t)n;
    }
    return 0;
}

static ssize_t read_now(const sb_posix *p, uint8_t *buf, size_t cap)
{
    return p->is_socket ? recv(p->fd, buf, cap, MSG_DONTWAIT) : read(p->fd, buf, cap);
}

/* A read that found no byte yet, as opposed to one that failed. */
static bool none_yet(ssize_t n)
{
    return n == 0 || (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR));
}

/* Up to spin_us (at most wait_us) of looking without sleeping: > 0 bytes
 * read, < 0 an error, 0 none came (*wait_us then what is left). */
static ssize_t spin(sb_posix *p, uint8_t *buf, size_t cap, uint32_t *wait_us)
{
    uint32_t most = p->spin_us < *wait_us ? p->spin_us : *wait_us;
    uint64_t start = sb_monotonic_us(NULL), spent = 0;
    ssize_t n = 0;
    while (most > 0 && spent < most) {
        n = read_now(p, buf, cap);
        if (!none_yet(n))
            return n;
        spent = sb_monotonic_us(NULL) - start;
    }
    *wait_us -= spent < *wait_us ? (uint32_t)spent : *wait_us;
    return 0;
}

static int posix_read(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us)
{
    sb_posix *p = (sb_posix *)ctx;
    bool waits = wait_us > 0;
    ssize_t n = waits ? spin(p, buf, cap, &wait_us) : 0;
    bool hung_up = false;
    if (n != 0)
        goto got;
    /* A wait polls even when the spin used all of it (a process the PC held
     * up in the spin): with no time left, the poll only says whether the
     * other end hung up, which a read of none does not. */
    if (waits) {
        struct pollfd pf = {p->fd, POLLIN, 0};
        struct timespec ts = {(time_t)(wait_us / 1000000u), (long)(wait_us % 1000000u) * 1000L};
        /* The socket reads as ready once want bytes are there, not at each
         * byte a simulator hands over (LOW_WATER_MOST at most). */
        if (want > LOW_WATER_MOST)
            want = LOW_WATER_MOST;
        if (p->is_socket && (int)want != p->low_water && want > 0) {
            int lw = (int)want;
            if (setsockopt(p->fd, SOL_SOCKET, SO_RCVLOWAT, &lw, sizeof lw) == 0)
                p->low_water = lw;
        }
        if (ppoll(&pf, 1, &ts, NULL) < 0 && errno != EINTR)
            return -errno;
        hung_up = (pf.revents & (POLLHUP | POLLERR)) != 0;
    }
    n = read_now(p, buf, cap);
got:
    if (n > 0 && p->is_socket && holds(buf, (size_t)n, BUS_IN_USE))
        return -EBUSY; /* the simulator's bus is another client's: nothing sent reached it */
    if (!none_yet(n))
        return n < 0 ? -errno : (int)n;
    if (n == 0 && p->is_socket)
        return -ECONNRESET; /* the other end closed the connection */
    if (hung_up)
        return -EIO; /* a pseudo-terminal whose other end closed, an adapter unplugged */
    return 0;
}

sb_transport sb_posix_transport(sb_posix *p)
{
    return sb_transport_make(p, posix_write, posix_read, sb_monotonic_us);
}
