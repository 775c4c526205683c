/* servobus's serial transport and a USB-serial adapter's latency timer:
 * read from sysfs (a folder standing for /sys here), set to 1 ms where it
 * is slower. */
#define _GNU_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pty.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "servobus/servobus_posix.h"

static char root[64];
static char timer[200];

static void put(const char *text)
{
    FILE *f = fopen(timer, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static int set_up(void **state)
{
    char dir[160];
    strcpy(root, "/tmp/servobus-sysfs-XXXXXX");
    assert_non_null(mkdtemp(root));
    snprintf(dir, sizeof dir, "%s/class", root);
    mkdir(dir, 0755);
    snprintf(dir, sizeof dir, "%s/class/tty", root);
    mkdir(dir, 0755);
    snprintf(dir, sizeof dir, "%s/class/tty/ttyUSB7", root);
    mkdir(dir, 0755);
    snprintf(dir, sizeof dir, "%s/class/tty/ttyUSB7/device", root);
    mkdir(dir, 0755);
    snprintf(timer, sizeof timer, "%s/latency_timer", dir);
    setenv("SERVOBUS_SYSFS", root, 1);
    return 0;
}

static int tear_down(void **state)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", root);
    unsetenv("SERVOBUS_SYSFS");
    return system(cmd);
}

static void the_latency_timer_is_read_and_set_to_1_ms(void **state)
{
    sb_posix p;
    memset(&p, 0, sizeof p);
    assert_int_equal(sb_serial_latency_timer("/dev/ttyUSB7"), -1);
    put("16\n");
    assert_int_equal(sb_serial_latency_timer("/dev/ttyUSB7"), 16);
    sb_serial_check_latency(&p, "/dev/ttyUSB7");
    assert_int_equal(p.latency_timer_ms, 1);
    assert_int_equal(sb_serial_latency_timer("/dev/ttyUSB7"), 1);
    assert_string_equal(p.advice, "");
}

static void a_timer_that_cannot_be_set_names_the_fix(void **state)
{
    sb_posix p;
    memset(&p, 0, sizeof p);
    /* A file no one may write, root included, that reads as a number
     * above 1: a read-only sysctl (its kernel's major version). */
    assert_int_equal(symlink("/proc/sys/kernel/osrelease", timer), 0);
    sb_serial_check_latency(&p, "/dev/ttyUSB7");
    assert_true(p.latency_timer_ms > 1);
    assert_non_null(strstr(p.advice, "echo 1 | sudo tee /sys/bus/usb-serial/devices/ttyUSB7/latency_timer"));
    assert_non_null(strstr(p.advice, "ttyUSB7's latency timer is "));
}

/* /dev/serial/by-id/usb-FTDI_...-port0 is a link to ../../ttyUSB7: the timer is ttyUSB7's. */
static void a_port_by_a_link_has_its_device_s_timer(void **state)
{
    sb_posix p;
    char dev[200], link[200];
    memset(&p, 0, sizeof p);
    snprintf(dev, sizeof dev, "%s/ttyUSB7", root);
    put("16\n");
    fclose(fopen(dev, "w"));
    snprintf(link, sizeof link, "%s/usb-FTDI_FT232R_USB_UART_A10K-if00-port0", root);
    assert_int_equal(symlink("ttyUSB7", link), 0);
    assert_int_equal(sb_serial_latency_timer(link), 16);
    sb_serial_check_latency(&p, link);
    assert_int_equal(p.latency_timer_ms, 1);
    assert_int_equal(sb_serial_latency_timer(dev), 1);
}

static void a_rate_termios_has_not_is_refused(void **state)
{
    sb_posix p;
    assert_int_equal(sb_serial_open(&p, "/dev/null", 250000), -22); /* -EINVAL */
    assert_true(sb_serial_open(&p, "/nonexistent/tty", 115200) < 0);
    /* A TCP port past 65535 is no port (getaddrinfo took 109223 as 43687). */
    assert_int_equal(sb_tcp_open(&p, "127.0.0.1", 65536u + 43687u), -22);
    assert_int_equal(sb_tcp_open(&p, "127.0.0.1", 0), -22);
}

/* servoctl (pyserial's exclusive=True) holds the port: two programs on one
 * bus would garble each other's frames. */
static void a_port_another_program_holds_is_refused(void **state)
{
    int master = -1, slave = -1, other;
    char name[128];
    sb_posix p;
    (void)state;
    assert_int_equal(openpty(&master, &slave, name, NULL, NULL), 0);
    other = open(name, O_RDWR | O_NOCTTY);
    assert_true(other >= 0);
    assert_int_equal(flock(other, LOCK_EX | LOCK_NB), 0);
    assert_int_equal(sb_serial_open(&p, name, 115200), -16); /* -EBUSY */
    assert_int_equal(p.fd, -1);
    close(other);
    assert_int_equal(sb_serial_open(&p, name, 115200), 0);
    sb_posix_close(&p);
    close(slave);
    close(master);
}

/* The serial transport on a pseudo-terminal: the test plays the far end. */
typedef struct pty_port {
    int master, slave;
    char name[128];
    sb_posix p;
    sb_transport t;
} pty_port;

static void open_pty_port(pty_port *port)
{
    port->master = port->slave = -1;
    assert_int_equal(openpty(&port->master, &port->slave, port->name, NULL, NULL), 0);
    assert_int_equal(sb_serial_open(&port->p, port->name, 115200), 0);
    port->t = sb_posix_transport(&port->p);
}

static void close_pty_far_end(pty_port *port)
{
    if (port->slave >= 0)
        close(port->slave);
    if (port->master >= 0)
        close(port->master);
    port->master = port->slave = -1;
}

static void close_pty_port(pty_port *port)
{
    sb_posix_close(&port->p);
    close_pty_far_end(port);
}

/* cmocka's set-up and tear-down for the tests that read from the port. */
static pty_port fixture_port;

static int open_fixture_port(void **state)
{
    open_pty_port(&fixture_port);
    *state = &fixture_port;
    return 0;
}

static int close_fixture_port(void **state)
{
    close_pty_port(*state);
    return 0;
}

/* A link that stops taking bytes (nobody reads the pty's master: a wedged
 * adapter) fails the write in about a second; it hung the loop for ever. */
static void a_write_the_link_never_takes_fails(void **state)
{
    int rc = 0;
    uint8_t frame[200];
    pty_port port;
    (void)state;
    memset(frame, 0x55, sizeof frame);
    open_pty_port(&port);
    alarm(20); /* the original waited for ever: ctest sees the alarm */
    for (int k = 0; k < 100000 && rc == 0; k++)
        rc = port.t.write(port.t.ctx, frame, sizeof frame);
    alarm(0);
    assert_int_equal(rc, -110); /* -ETIMEDOUT */
    close_pty_port(&port);
}

/* A wait looks for bytes without sleeping first (spin_us), then sleeps
 * for the rest; bytes there, or come meanwhile, are read either way, and
 * none in the wait is no error. */
static void a_wait_spins_then_sleeps_and_reads_what_comes(void **state)
{
    uint8_t buf[16];
    pty_port *port = *state;
    sb_transport *t = &port->t;
    assert_int_equal(port->p.spin_us, SB_POSIX_SPIN_US);
    assert_int_equal(t->read(t->ctx, buf, sizeof buf, 1, 2000), 0); /* spun, slept: nothing */
    assert_int_equal(write(port->master, "\x55\xAA", 2), 2);
    assert_int_equal(t->read(t->ctx, buf, sizeof buf, 2, 1000000), 2); /* found while spinning */
    assert_int_equal(buf[0], 0x55);
    port->p.spin_us = 0; /* sleeps at once */
    assert_int_equal(write(port->master, "\x01", 1), 1);
    assert_int_equal(t->read(t->ctx, buf, sizeof buf, 1, 1000000), 1);
    assert_int_equal(buf[0], 0x01);
}

/* servo_sim killed under a loop on its pseudo-terminal: the wait reported
 * "nothing yet" for ever (the hang-up read as no bytes). */
static void a_port_whose_other_end_hung_up_fails(void **state)
{
    uint8_t buf[16];
    pty_port *port = *state;
    sb_transport *t = &port->t;
    assert_int_equal(t->read(t->ctx, buf, sizeof buf, 1, 1000), 0); /* open, quiet */
    close_pty_far_end(port);
    assert_true(t->read(t->ctx, buf, sizeof buf, 1, 1000000) < 0); /* a wait sees it; a drain's look need not */
}

/* The same when the spin took all of the wait, as when the PC held the
 * process up in it: the wait skipped its poll and said "nothing yet". */
static void a_hang_up_is_seen_when_the_spin_took_the_whole_wait(void **state)
{
    uint8_t buf[16];
    pty_port *port = *state;
    sb_transport *t = &port->t;
    port->p.spin_us = 1000000u; /* longer than the wait: the spin takes all of it */
    close_pty_far_end(port);
    assert_true(t->read(t->ctx, buf, sizeof buf, 1, 2000) < 0);
}

/* A TCP listener on the loopback at a free port, given in port. */
static int loopback_listener(unsigned *port)
{
    int listener = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in at = {0};
    socklen_t len = sizeof at;
    at.sin_family = AF_INET;
    at.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(listener, (struct sockaddr *)&at, sizeof at), 0);
    assert_int_equal(listen(listener, 1), 0);
    assert_int_equal(getsockname(listener, (struct sockaddr *)&at, &len), 0);
    *port = ntohs(at.sin_port);
    return listener;
}

/* A simulator whose bus another client holds says so to a second one,
 * and sends nothing more: servobus said "no answer in time (is it on
 * the bus ...)" and a send returned SB_OK though nothing reached the bus. */
static void a_bus_another_client_holds_is_said_so(void **state)
{
    unsigned port;
    int listener = loopback_listener(&port);
    sb_posix link;
    assert_int_equal(sb_tcp_open(&link, "127.0.0.1", port), 0);
    int server = accept(listener, NULL, NULL);
    const char said[] = "servo_sim: the bus is in use by another client\n";
    assert_int_equal(write(server, said, sizeof said - 1), (ssize_t)(sizeof said - 1));
    sb_bus bus;
    sb_bus_init(&bus, sb_posix_transport(&link), 115200);
    sb_ping_request r = {1};
    sb_ping_answer a;
    usleep(20000); /* the message is there before the request */
    sb_error e = sb_call_ping(&bus, &r, &a);
    assert_int_equal(e.status, SB_E_LINK);
    assert_int_equal(e.os_error, EBUSY);
    char text[200];
    sb_error_text(&e, text, sizeof text);
    assert_non_null(strstr(text, "another program holds the bus"));
    close(server);
    close(listener);
    sb_posix_close(&link);
}

/* The link's poll() (linked with --wrap=poll): given a descriptor in
 * hold_poll, the next poll first waits for a byte on it, so that the
 * simulator's process has spoken by the time the open looks (for 50 ms of
 * the host's time, which a loaded PC may not give a process to wake in). */
int __real_poll(struct pollfd *fds, nfds_t n, int timeout_ms);
static int hold_poll = -1;

int __wrap_poll(struct pollfd *fds, nfds_t n, int timeout_ms)
{
    if (hold_poll >= 0) {
        char spoke;
        int fd = hold_poll;
        hold_poll = -1;
        if (read(fd, &spoke, 1) != 1)
            return -1;
    }
    return __real_poll(fds, n, timeout_ms);
}

/* The same told at once, as servo_sim tells it: the open itself says so,
 * so a program that only sends (sb_send_move_angle returned SB_OK while
 * nothing reached the bus) is not fooled. */
static void an_open_of_a_bus_another_client_holds_is_refused(void **state)
{
    unsigned port;
    int listener = loopback_listener(&port);
    int spoke[2];
    assert_int_equal(pipe(spoke), 0);
    pid_t child = fork();
    if (child == 0) { /* the simulator: tells the client at once, then holds the line */
        int server = accept(listener, NULL, NULL);
        const char said[] = "servo_sim: the bus is in use by another client\n";
        if (write(server, said, sizeof said - 1) < 0 || write(spoke[1], "", 1) != 1)
            _exit(1);
        usleep(300000);
        _exit(0);
    }
    sb_posix link;
    hold_poll = spoke[0];
    alarm(20); /* a child that never speaks: ctest sees the alarm */
    assert_int_equal(sb_tcp_open(&link, "127.0.0.1", port), -EBUSY);
    alarm(0);
    hold_poll = -1;
    int status = 0;
    waitpid(child, &status, 0);
    close(spoke[0]);
    close(spoke[1]);
    close(listener);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(the_latency_timer_is_read_and_set_to_1_ms, set_up, tear_down),
        cmocka_unit_test_setup_teardown(a_port_by_a_link_has_its_device_s_timer, set_up, tear_down),
        cmocka_unit_test_setup_teardown(a_timer_that_cannot_be_set_names_the_fix, set_up, tear_down),
        cmocka_unit_test(a_rate_termios_has_not_is_refused),
        cmocka_unit_test(a_port_another_program_holds_is_refused),
        cmocka_unit_test(a_write_the_link_never_takes_fails),
        cmocka_unit_test(a_bus_another_client_holds_is_said_so),
        cmocka_unit_test(an_open_of_a_bus_another_client_holds_is_refused),
        cmocka_unit_test_setup_teardown(a_wait_spins_then_sleeps_and_reads_what_comes, open_fixture_port,
                                        close_fixture_port),
        cmocka_unit_test_setup_teardown(a_port_whose_other_end_hung_up_fails, open_fixture_port, close_fixture_port),
        cmocka_unit_test_setup_teardown(a_hang_up_is_seen_when_the_spin_took_the_whole_wait, open_fixture_port,
                                        close_fixture_port),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
