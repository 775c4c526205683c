/* servo_sim: the servo firmware on simulated servos, on a pseudo-terminal
 * or a TCP port, in real time. See `servo_sim --help` and README.md. */
#define _GNU_SOURCE

#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "host_baud.h"
#include "sim_bus.h"
#include "sim_clock.h"
#include "sim_control.h"
#include "sim_link.h"
#include "sim_options.h"
#include "sim_servo.h"

static struct sim_bus bus;
/* Furthest the bus clock has fallen behind the wall clock (a busy PC). */
static uint64_t most_behind_us;
static struct sim_servo servos[SIM_MAX_SERVOS];
static volatile sig_atomic_t stop_requested;
/* How many bytes the host had been sent when it last sent bytes itself. */
static unsigned long host_bytes_then;
/* --clock paced (sim_clock.h). */
static bool paced_clock;
/* Bytes read from the host in all (a paced host's offset 16, sim_clock.h). */
static uint64_t host_read_total;
/* A second TCP client while one holds the bus is told so and then ignored
 * until it leaves: a serial port has one program at a time, and two hosts
 * on a half-duplex bus would talk over each other. The words are what
 * servoctl recognises (protocol.py, BUS_IN_USE). */
#define BUS_IN_USE "servo_sim: the bus is in use by another client\n"
enum { REFUSED_MAX = 4 };
/* How long the servos run before the simulator says it is ready: their
 * first control ticks (1 ms apart) have run by then. */
enum { READY_AFTER_US = 5000 };
/* How often a paced simulator standing still looks at the host's clock
 * word (sim_clock.h) when no byte wakes it. */
enum { PACED_POLL_US = 200 };
/* How long after its last byte the host counts as taking its turn. */
enum { HOST_TURN_US = 50000 };
/* For this long of it the simulator does not sleep: a host that answers
 * within it has its bytes taken at the bus time they came, not when the PC
 * woke the simulator (or when the simulator went to sleep). */
enum { HOST_SPIN_US = 200 };
/* When the host was last handed bytes: the bus clock then, and the wall
 * clock (sim_now_us) as the simulator handed them over. */
static uint64_t handed_bus_us, handed_wall_us;
enum { PACED_START_US = 1000 }; /* a paced clock's start: the wall clock's */
static int refused[REFUSED_MAX] = {-1, -1, -1, -1};
/* A client that came while the one on the bus had hung up, its last bytes
 * unread (a loaded PC held this process up): taken once those bytes are
 * read and the leaving seen, not told the bus is in use. -1: none. */
static int next_fd = -1;

/* The TCP client on the bus has hung up (its bytes may still be unread). */
static bool host_hung_up(void)
{
    struct pollfd p = {.fd = bus.host_fd, .events = POLLRDHUP};
    return poll(&p, 1, 0) == 1 && (p.revents & (POLLRDHUP | POLLHUP | POLLERR));
}

static void take_client(int fd)
{
    int one = 1; /* a UART does not wait to fill packets */
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    sim_stamp_arrivals(fd);
    fcntl(fd, F_SETFL, O_NONBLOCK);
    bus.host_fd = fd;
    sim_bus_new_host(&bus); /* the answers to one that left are not its */
}

static void tell_in_use(int fd)
{
    ssize_t w = write(fd, BUS_IN_USE, sizeof BUS_IN_USE - 1u);
    (void)w; /* a client already gone needs no reason */
}

/* Told at once and at every request it sends: a client that flushes its
 * input as it opens (pyserial) would miss the first telling. */
static void refuse(int fd)
{
    tell_in_use(fd);
    for (int i = 0; i < REFUSED_MAX; i++) {
        if (refused[i] < 0) {
            fcntl(fd, F_SETFL, O_NONBLOCK);
            refused[i] = fd; /* kept open: closed at once, its words could be lost */
            return;
        }
    }
    close(fd);
}

/* A host that waits for an answer (sim_clock.h) has it: it has been sent
 * bytes since its last, bytes it has not read yet (a paced host says what
 * it has read), and the wire and its adapter hold none. */
static bool host_answered(uint64_t waits)
{
    return (waits & SIM_CLOCK_UNTIL_ANSWER) && bus.host_bytes != host_bytes_then &&
           bus.host_bytes > sim_clock_host_received() && bus.count == 0 && sim_usb_due(&bus.usb) == SIM_USB_NONE;
}

/* The host takes its turn: it has been handed bytes since it last wrote,
 * the wire and its adapter are quiet, its last byte within within_us. */
static bool host_turn(uint64_t wall_us, uint64_t within_us)
{
    /* A host that moves the clock itself (its waits in the clock file,
     * sim_clock.h: servoctl's fast and paced simulators) is not timed in
     * real time: a simulator behind catches up at once for it, and may
     * then run ahead. */
    return sim_clock_host_waits() == 0u && bus.host_bytes != host_bytes_then && bus.count == 0 &&
           sim_usb_due(&bus.usb) == SIM_USB_NONE && wall_us - handed_wall_us < within_us;
}

/* The servos and the wire up to target on the bus clock, event by event:
 * each byte as it ends on the wire, and each servo's main-loop pass when
 * its CPU would run it (sim_servo_wake_at): when the loop was late, the
 * bytes it catches up on do not all land before a servo has seen the
 * first, and an answer leaves when the target's CPU would have sent it.
 * until_answer (paced, sim_clock.h): up to the event that completes the
 * host's answer, at most; where the host then is does not depend on when
 * it sends its next bytes. */
static void run_to(uint64_t target, bool until_answer)
{
    do {
        uint64_t next = sim_bus_next_at(&bus, target);
        for (unsigned i = 0; i < bus.station_count; i++) {
            uint64_t wake = sim_servo_wake_at(&servos[i]);
            next = wake < next ? wake : next;
        }
        uint64_t at = next > bus.now_us ? next : bus.now_us;
        if (paced_clock && at > bus.now_us) {
            /* Before the bytes it hands the host: a host that reads the clock
             * once it has its answer reads the answer's time, not a step's
             * before it. */
            sim_clock_publish(at);
        }
        unsigned long host_bytes = bus.host_bytes;
        sim_bus_deliver(&bus, at);
        if (bus.host_bytes != host_bytes) {
            handed_bus_us = bus.now_us;
            handed_wall_us = bus.handed_wall_us; /* before the write: the host may start at once */
        }
        for (unsigned i = 0; i < bus.station_count; i++) {
            sim_servo_poll(&servos[i], bus.now_us);
        }
        if (until_answer && host_answered(SIM_CLOCK_UNTIL_ANSWER)) {
            break;
        }
        if (!paced_clock && bus.host_bytes != host_bytes && host_turn(sim_now_us(), HOST_TURN_US)) {
            break; /* the host's turn runs from here, on the wall clock (host_turn_bound) */
        }
    } while (bus.now_us < target);
    sim_clock_publish(bus.now_us);
}

/* A paced simulator runs while its host waits for a later time, or for an
 * answer not yet given, once it has read every byte the host has sent. */
static bool paced_may_run(bool answered, uint64_t waits)
{
    return !answered && waits > bus.now_us && sim_clock_host_sent() <= host_read_total;
}

/* Where a simulator behind the wall clock may run to while its host takes
 * its turn: no further than the wall time since the host was handed its
 * last byte. The host's reaction time is its own, real time; caught up at
 * full speed meanwhile, the bus clock would charge the host with the
 * simulator's lag (a 16-servo round that the simulator ran slower than
 * real time: 0.25-1 ms of host gap, scripts/c_loop_bench.sh). */
static uint64_t host_turn_bound(uint64_t target, uint64_t wall_us)
{
    if (!host_turn(wall_us, HOST_TURN_US)) {
        return target;
    }
    uint64_t bound = handed_bus_us + (wall_us - handed_wall_us);
    bound = bound > bus.now_us ? bound : bus.now_us;
    return bound < target ? bound : target;
}

/* Where the host's bytes just read go on the wire: at the bus clock; in a
 * real-time host's turn, at the wall time it took since its last byte
 * (host_turn_bound) until they arrived (ago_us before now), not at the bus
 * time of the simulator's last pass. */
static uint64_t host_bytes_at(bool paced, uint64_t ago_us)
{
    uint64_t wall_us = sim_now_us();
    wall_us -= ago_us < wall_us - handed_wall_us ? ago_us : wall_us - handed_wall_us;
    if (paced || !host_turn(wall_us, HOST_TURN_US)) {
        return bus.now_us;
    }
    return host_turn_bound(sim_bus_step_to(&bus, wall_us), wall_us);
}

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

int main(int argc, char **argv)
{
    struct sim_options o;
    sim_options_parse(argc, argv, &o);
    paced_clock = o.paced;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN);
    mkdir(o.state_dir, 0755);

    uint64_t wall_start = sim_now_us();
    sim_bus_init(&bus, o.paced ? PACED_START_US : wall_start); /* paced: every run alike */
    bus.usb = o.host_link;
    bus.wall_us = sim_now_us;
    char clock_path[256];
    bool clock_mapped = sim_clock_open(o.state_dir, clock_path, sizeof clock_path);
    for (unsigned i = 0; i < o.id_count; i++) {
        servos[i].cpu = o.cpu;
        if (!sim_servo_start(&servos[i], &bus, i, o.ids[i], o.units[i], o.state_dir, &o.plant,
                             o.supply_v, o.ambient_c)) {
            return 1;
        }
        servos[i].rx_interrupt = o.rx_interrupt;
        sim_bus_attach(&bus, sim_servo_station(&servos[i]));
    }

    int listen_fd = -1;
    int slave_fd = -1;
    int bound = 0;
    char where[128];
    if (o.tcp_port >= 0) {
        listen_fd = sim_listen_on(o.tcp_port, &bound);
        snprintf(where, sizeof where, "socket://127.0.0.1:%d", bound);
    } else {
        bus.host_fd = sim_open_pty(o.link, where, sizeof where, &slave_fd);
    }
    struct sim_control control;
    sim_control_open(&control, o.control_port, &bus, servos, &most_behind_us);
    /* The servos run the first READY_AFTER_US of their power-up before
     * "ready": the first requests find their first control ticks run and
     * their readings (IDs 1-4) taken, as a host finds a servo after its
     * power-up, however long the PC then keeps this process waiting. */
    uint64_t ready_at = bus.now_us + READY_AFTER_US;
    while (bus.now_us < ready_at) {
        /* Paced: in whole steps, whatever the wall clock (sim_clock.h). */
        uint64_t to = o.paced ? bus.now_us + SIM_BUS_STEP_US : sim_bus_step_to(&bus, sim_now_us());
        run_to(to < ready_at ? to : ready_at, false);
    }

    printf("servo_sim: plant %s\n", o.plant.name);
    printf("servo_sim: bus %s\n", where);
    if (o.link) {
        printf("servo_sim: link %s\n", o.link);
    }
    printf("servo_sim: control 127.0.0.1:%d\n", control.port);
    if (clock_mapped) {
        printf("servo_sim: clock %s\n", clock_path);
    }
    printf("servo_sim: servos");
    for (unsigned i = 0; i < o.id_count; i++) {
        printf(" %u", o.ids[i]);
    }
    printf("\nservo_sim: ready\n");
    fflush(stdout);

    while (!stop_requested) {
        struct pollfd fds[2 + REFUSED_MAX + SIM_CONTROL_FDS];
        int nfds = 0;
        int host_slot = -1, listen_slot = -1, refused_slot, control_slot;
        /* A host that writes faster than the line waits (it is not read),
         * as behind its own UART. */
        if (bus.host_fd >= 0) {
            host_slot = nfds;
            short events = sim_bus_room(&bus) >= 512u ? POLLIN : 0;
            fds[nfds++] = (struct pollfd){.fd = bus.host_fd, .events = events};
        }
        if (listen_fd >= 0) {
            listen_slot = nfds;
            fds[nfds++] = (struct pollfd){.fd = listen_fd, .events = POLLIN};
        }
        refused_slot = nfds;
        for (int i = 0; i < REFUSED_MAX; i++) {
            fds[nfds++] = (struct pollfd){.fd = refused[i], .events = POLLIN};
        }
        control_slot = nfds;
        sim_control_fds(&control, &fds[control_slot]);
        nfds += SIM_CONTROL_FDS;
        /* Wake often enough for every control tick and bus byte; not at all
         * while the bus clock is behind the wall clock. */
        uint64_t wall = sim_now_us();
        int64_t due = sim_bus_next_due(&bus, wall);
        long wait_us = (due >= 0 && due < SIM_BUS_STEP_US) ? (long)due : SIM_BUS_STEP_US;
        uint64_t waits = sim_clock_host_waits();
        bool answered = host_answered(waits);
        waits &= ~SIM_CLOCK_UNTIL_ANSWER;
        if (o.paced) {
            wait_us = paced_may_run(answered, waits) ? 0 : PACED_POLL_US;
        } else if (host_turn_bound(wall, wall) > bus.now_us + SIM_BUS_STEP_US ||
                   (waits > wall && !answered) || host_turn(wall, HOST_SPIN_US)) {
            /* A step behind where it may run (the wall clock; in the host's
             * turn, the wall time since its last byte: else each oversleep
             * is lost), or running ahead for the host, or its turn begun. */
            wait_us = 0;
        }
        struct timespec timeout = {.tv_sec = 0, .tv_nsec = wait_us * 1000};
        if (ppoll(fds, (nfds_t)nfds, &timeout, NULL) < 0 && errno != EINTR) {
            perror("servo_sim: poll");
            break;
        }
        if (slave_fd >= 0) {
            uint32_t baud = host_baud_of(slave_fd);
            bus.host_baud = baud != 0u ? baud : bus.host_baud;
        }
        if (host_slot >= 0 && (fds[host_slot].revents & (POLLIN | POLLHUP | POLLERR)) &&
            sim_bus_room(&bus) >= 512u) {
            uint8_t buf[512];
            uint64_t ago_us;
            ssize_t n = sim_read_host(bus.host_fd, buf, sizeof buf, &ago_us);
            if (n > 0) {
                sim_bus_from_host(&bus, buf, (unsigned)n, host_bytes_at(o.paced, ago_us));
                host_bytes_then = bus.host_bytes;
                host_read_total += (uint64_t)n;
            } else if (listen_fd >= 0 && (n == 0 || errno != EAGAIN)) {
                close(bus.host_fd); /* the TCP client left: wait for the next */
                bus.host_fd = -1;
                if (next_fd >= 0) {
                    take_client(next_fd);
                    next_fd = -1;
                }
            }
        }
        for (int i = 0; i < REFUSED_MAX; i++) { /* a refused client left, or wrote: drained */
            if (refused[i] >= 0 && (fds[refused_slot + i].revents & (POLLIN | POLLHUP | POLLERR))) {
                uint8_t drop[256];
                ssize_t n = read(refused[i], drop, sizeof drop);
                if (n == 0 || (n < 0 && errno != EAGAIN)) {
                    close(refused[i]);
                    refused[i] = -1;
                } else if (n > 0) {
                    tell_in_use(refused[i]);
                }
            }
        }
        /* After the host's read: a client that left and one that came in
         * its place are seen in that order. */
        if (listen_slot >= 0 && (fds[listen_slot].revents & POLLIN)) {
            int fd = accept(listen_fd, NULL, NULL);
            if (fd >= 0 && bus.host_fd >= 0 && next_fd < 0 && host_hung_up()) {
                next_fd = fd;
            } else if (fd >= 0 && bus.host_fd >= 0) {
                refuse(fd);
            } else if (fd >= 0) {
                take_client(fd);
            }
        }
        sim_control_serve(&control, &fds[control_slot]);
        /* A host waiting for a later bus time: one step of it at once (its
         * bytes are still read between steps), not in real time; one that
         * waits for an answer has its turn once it has been sent bytes
         * since it last wrote and the wire is quiet. */
        waits = sim_clock_host_waits();
        answered = host_answered(waits);
        if (o.paced) {
            bool until_answer = (waits & SIM_CLOCK_UNTIL_ANSWER) != 0u;
            waits &= ~SIM_CLOCK_UNTIL_ANSWER;
            if (paced_may_run(answered, waits)) {
                uint64_t step = bus.now_us + SIM_BUS_STEP_US;
                run_to(step < waits ? step : waits, until_answer);
            }
            continue; /* paced: never the wall clock's */
        }
        waits &= ~SIM_CLOCK_UNTIL_ANSWER;
        uint64_t wall_now = sim_now_us();
        if (!answered && waits > wall_now && bus.now_us + SIM_BUS_STEP_US >= wall_now) {
            uint64_t skip = waits - wall_now;
            sim_skip_us(skip < SIM_BUS_STEP_US ? skip : SIM_BUS_STEP_US);
            wall_now = sim_now_us();
        }
        uint64_t target = host_turn_bound(sim_bus_step_to(&bus, wall_now), wall_now);
        if (wall_now - target > most_behind_us) {
            most_behind_us = wall_now - target;
        }
        run_to(target, false);
    }
    if (o.link) {
        unlink(o.link);
    }
    if (clock_mapped) {
        unlink(clock_path);
    }
    printf("servo_sim: stopped (%lu collisions)\n", bus.collisions);
    return 0;
}
