/* servo_sim: the servo firmware on simulated servos, on a pseudo-terminal
 * or a TCP port, in real time. See `servo_sim --help` and README.md. */
#define _GNU_SOURCE

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "host_baud.h"
#include "sim_bus.h"
#include "sim_servo.h"

#define MAX_CONTROL_CLIENTS 8

struct options {
    uint8_t ids[SIM_MAX_SERVOS];
    unsigned id_count;
    int tcp_port;          /* 0: a pseudo-terminal */
    int control_port;      /* 0: any free port */
    const char *link;      /* symlink to the pty */
    const char *state_dir;
    double supply_v;
    double ambient_c;
    bool rx_interrupt;
};

struct control_client {
    int fd;
    char line[256];
    size_t used;
};

static struct sim_bus bus;
static struct sim_servo servos[SIM_MAX_SERVOS];
static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

static void usage(FILE *out)
{
    fputs("usage: servo_sim [--id N]... [--tcp PORT | --link PATH] [--control PORT]\n"
          "                 [--state DIR] [--supply MV] [--ambient DEGC]\n"
          "Runs the servo firmware on simulated servos sharing one bus.\n"
          "  --id N         a servo with ID N (repeat for more; default 1)\n"
          "  --tcp PORT     the bus on 127.0.0.1:PORT (pyserial socket://) instead of a pty\n"
          "  --link PATH    also make PATH a symlink to the pty\n"
          "  --control PORT fault injection on 127.0.0.1:PORT (default: any free port)\n"
          "  --state DIR    where each servo's flash file lives (default ./sim-state)\n"
          "  --supply MV    supply voltage (default 7400)\n"
          "  --ambient DEGC ambient temperature (default 25)\n"
          "  --rx dma|interrupt  how the port receives: DMA into a ring (the reference\n"
          "                 board, default) or a byte per interrupt, which overruns\n"
          "                 while the flash stalls the CPU\n"
          "Control commands, one per line, optional servo ID last:\n"
          "  supply MV | load NM | stop DEG | stop off | ambient DEGC | soak DEGC |\n"
          "  hostbaud BAUD (a TCP host's rate; a pty's is what the host set) |\n"
          "  failerase N | failprogram N (the next N flash erases, or half-word\n"
          "  programs, of the config store and the slot fail, as a worn page's do) |\n"
          "  powercycle (the servo restarts through its bootloader) | state | help |\n"
          "  clock (the simulated clock, sim_ms, and how far it is behind the wall clock) |\n"
          "  hostsend MS HEX (the host's bytes on the wire from simulated time MS)\n"
          "The servos run on the simulated clock: it follows the wall clock, and falls\n"
          "behind it on a busy PC. state gives each servo's sim_ms with its models,\n"
          "last_move_ms (how long status bit 0 was last set) and last_sent_ms (when its\n"
          "last answer started), all on that clock.\n",
          out);
}

static int parse_int(const char *s, const char *what, long lo, long hi)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (*s == '\0' || *end != '\0' || v < lo || v > hi) {
        fprintf(stderr, "servo_sim: %s must be a whole number from %ld to %ld, not '%s'\n", what,
                lo, hi, s);
        exit(2);
    }
    return (int)v;
}

static void parse(int argc, char **argv, struct options *o)
{
    *o = (struct options){.state_dir = "sim-state", .supply_v = 7.4, .ambient_c = 25.0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "servo_sim: %s needs a value\n", a);
            usage(stderr);
            exit(2);
        }
        const char *v = argv[++i];
        if (strcmp(a, "--id") == 0) {
            if (o->id_count == SIM_MAX_SERVOS) {
                fprintf(stderr, "servo_sim: at most %u servos\n", SIM_MAX_SERVOS);
                exit(2);
            }
            uint8_t id = (uint8_t)parse_int(v, "--id", 0, 254);
            for (unsigned k = 0; k < o->id_count; k++) {
                if (o->ids[k] == id) {
                    fprintf(stderr, "servo_sim: ID %u given twice\n", id);
                    exit(2);
                }
            }
            o->ids[o->id_count++] = id;
        } else if (strcmp(a, "--tcp") == 0) {
            o->tcp_port = parse_int(v, "--tcp", 1, 65535);
        } else if (strcmp(a, "--control") == 0) {
            o->control_port = parse_int(v, "--control", 1, 65535);
        } else if (strcmp(a, "--link") == 0) {
            o->link = v;
        } else if (strcmp(a, "--state") == 0) {
            o->state_dir = v;
        } else if (strcmp(a, "--supply") == 0) {
            o->supply_v = parse_int(v, "--supply", 0, 30000) / 1000.0;
        } else if (strcmp(a, "--ambient") == 0) {
            o->ambient_c = parse_int(v, "--ambient", -40, 150);
        } else if (strcmp(a, "--rx") == 0) {
            if (strcmp(v, "dma") != 0 && strcmp(v, "interrupt") != 0) {
                fprintf(stderr, "servo_sim: --rx is dma or interrupt, not '%s'\n", v);
                exit(2);
            }
            o->rx_interrupt = strcmp(v, "interrupt") == 0;
        } else {
            fprintf(stderr, "servo_sim: unknown option %s\n", a);
            usage(stderr);
            exit(2);
        }
    }
    if (o->id_count == 0) {
        o->ids[o->id_count++] = 1;
    }
}

static int listen_on(int port, int *bound_port)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in addr = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, (struct sockaddr *)&addr, sizeof addr) != 0 || listen(fd, 4) != 0) {
        fprintf(stderr, "servo_sim: cannot listen on 127.0.0.1:%d: %s\n", port, strerror(errno));
        exit(1);
    }
    socklen_t len = sizeof addr;
    getsockname(fd, (struct sockaddr *)&addr, &len);
    *bound_port = ntohs(addr.sin_port);
    return fd;
}

/* A pty in raw mode; the slave stays open so the master never sees EIO
 * between clients. */
static int open_pty(const char *link, char *name, size_t name_size, int *slave_fd)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
        fprintf(stderr, "servo_sim: cannot make a pseudo-terminal: %s\n", strerror(errno));
        exit(1);
    }
    snprintf(name, name_size, "%s", ptsname(master));
    *slave_fd = open(name, O_RDWR | O_NOCTTY);
    struct termios t;
    if (*slave_fd >= 0 && tcgetattr(*slave_fd, &t) == 0) {
        cfmakeraw(&t);
        tcsetattr(*slave_fd, TCSANOW, &t);
    }
    if (link != NULL) {
        unlink(link);
        if (symlink(name, link) != 0) {
            fprintf(stderr, "servo_sim: cannot link %s to %s: %s\n", link, name, strerror(errno));
            exit(1);
        }
    }
    return master;
}

static struct sim_servo *servo_by_id(int id)
{
    for (unsigned i = 0; i < bus.station_count; i++) {
        if (servos[i].cmdline_id == id) {
            return &servos[i];
        }
    }
    return NULL;
}

static void reply(int fd, const char *text)
{
    size_t n = strlen(text);
    while (n > 0) {
        ssize_t w = write(fd, text, n);
        if (w <= 0) {
            return;
        }
        text += w;
        n -= (size_t)w;
    }
}

/* Furthest the bus clock has fallen behind the wall clock (a busy PC). */
static uint64_t most_behind_us;

static void state_of(const struct sim_servo *s, char *out, size_t size)
{
    struct motion_angle a;
    motion_read_angle(&s->core.motion, &a);
    snprintf(out, size,
             "id=%u sim_ms=%.3f last_move_ms=%.3f last_sent_ms=%.3f "
             "angle=%.3f velocity=%.2f current=%.3f winding=%.2f case=%.2f ambient=%.1f "
             "supply=%.3f "
             "load=%.3f stop=%s status=0x%02x reported=%d collisions=%lu dropped_ticks=%u "
             "most_behind_ms=%.1f baud=%u host_baud=%u baud_mismatches=%lu rx_overruns=%u "
             "rx_lost=%u flash_stall_ms=%.2f saves=%u mode=%s version=0x%04x\n",
             s->cmdline_id, (double)bus.now_us / 1000.0, (double)s->last_execution_us / 1000.0,
             (double)s->last_sent_us / 1000.0, plant_angle_deg(&s->plant),
             s->plant.velocity * 180.0 / M_PI,
             s->plant.current, s->thermal.winding_c, s->thermal.case_c, s->thermal.ambient_c,
             s->plant.p.supply_v,
             s->plant.load_torque, s->plant.has_stop ? "on" : "off", s->core.regs.status.status,
             a.multi_turn_decideg, bus.collisions, s->core.ticks_dropped,
             (double)most_behind_us / 1000.0, (unsigned)s->baud, (unsigned)bus.host_baud,
             bus.baud_mismatches, (unsigned)s->rx.overruns, (unsigned)s->core.rx_lost,
             (double)s->flash_stall_us / 1000.0, (unsigned)s->core.store.sequence,
             s->in_bootloader ? "bootloader" : "app", (unsigned)s->core.regs.status.firmware_version);
}

/* "hostsend MS HEX": the host's bytes on the wire from simulated time MS
 * on (or at once, if that has passed), as the host's UART would send them.
 * A test times a frame into a window of a few milliseconds this way,
 * which a host process on a loaded PC cannot. */
static void host_send(int fd, int n, char **words)
{
    uint8_t data[100]; /* 200 hex digits: a control line holds 255 characters */
    size_t len = n == 3 ? strlen(words[2]) / 2u : 0u;
    char *end = NULL;
    double at_ms = n == 3 ? strtod(words[1], &end) : -1.0;
    if (n != 3 || end == words[1] || *end != '\0' || !(at_ms >= 0.0) || len == 0u ||
        len > sizeof data || strlen(words[2]) % 2u != 0u) {
        reply(fd, "error: hostsend takes a time in ms and 1 to 100 bytes in hex\n");
        return;
    }
    for (size_t i = 0; i < len; i++) {
        unsigned byte;
        if (sscanf(&words[2][2u * i], "%2x", &byte) != 1) {
            reply(fd, "error: hostsend takes a time in ms and 1 to 100 bytes in hex\n");
            return;
        }
        data[i] = (uint8_t)byte;
    }
    uint64_t at_us = (uint64_t)(at_ms * 1000.0);
    sim_bus_from_host(&bus, data, (unsigned)len, at_us > bus.now_us ? at_us : bus.now_us);
    reply(fd, "ok\n");
}

/* One control line: "command [value] [servo id]". */
static void control_command(int fd, char *line)
{
    char *words[4] = {0};
    int n = 0;
    for (char *t = strtok(line, " \t\r\n"); t != NULL && n < 4; t = strtok(NULL, " \t\r\n")) {
        words[n++] = t;
    }
    if (n == 0) {
        return;
    }
    const char *cmd = words[0];
    if (strcmp(cmd, "clock") == 0) {
        char out[96];
        snprintf(out, sizeof out, "sim_ms=%.3f behind_ms=%.1f\n", (double)bus.now_us / 1000.0,
                 (double)(sim_now_us() - bus.now_us) / 1000.0);
        reply(fd, out);
        return;
    }
    if (strcmp(cmd, "hostsend") == 0) {
        host_send(fd, n, words);
        return;
    }
    bool takes_value = strcmp(cmd, "state") != 0 && strcmp(cmd, "help") != 0 &&
                       strcmp(cmd, "powercycle") != 0;
    int id_word = takes_value ? 2 : 1;
    struct sim_servo *only = NULL;
    if (n > id_word) {
        only = servo_by_id(atoi(words[id_word]));
        if (only == NULL) {
            reply(fd, "error: no servo with that ID\n");
            return;
        }
    }
    if (strcmp(cmd, "help") == 0) {
        reply(fd, "ok supply MV | load NM | stop DEG | stop off | ambient DEGC | soak DEGC | "
                  "hostbaud BAUD | failerase N | failprogram N | powercycle [ID] | state [ID] | "
                  "clock | hostsend MS HEX\n");
        return;
    }
    if (takes_value && n < 2) {
        reply(fd, "error: missing value\n");
        return;
    }
    char *end = NULL;
    double value = takes_value ? strtod(words[1], &end) : 0.0;
    bool off = takes_value && strcmp(words[1], "off") == 0;
    if (takes_value && !off && (end == words[1] || *end != '\0')) {
        reply(fd, "error: the value must be a number\n");
        return;
    }
    /* What each model can take: a NaN or an infinity would stay in the
     * plant for good. */
    static const struct {
        const char *cmd;
        double lo, hi;
        const char *unit;
    } ranges[] = {
        {"supply", 0, 30000, "mV"},   {"load", -50, 50, "N m"},
        {"ambient", -40, 150, "degC"}, {"soak", -40, 150, "degC"},
        {"stop", -1e6, 1e6, "deg"},    {"hostbaud", 1200, 4000000, "baud"},
        {"failerase", 0, 1000000, "erases"}, {"failprogram", 0, 1000000, "programs"},
    };
    for (size_t r = 0; takes_value && !off && r < sizeof ranges / sizeof ranges[0]; r++) {
        if (strcmp(cmd, ranges[r].cmd) == 0 && !(value >= ranges[r].lo && value <= ranges[r].hi)) {
            char msg[128];
            snprintf(msg, sizeof msg, "error: %s takes %g to %g %s, not %s\n", cmd, ranges[r].lo,
                     ranges[r].hi, ranges[r].unit, words[1]);
            reply(fd, msg);
            return;
        }
    }
    if (off && strcmp(cmd, "stop") != 0) {
        reply(fd, "error: only stop takes off\n");
        return;
    }
    if (strcmp(cmd, "hostbaud") == 0) {
        bus.host_baud = (uint32_t)value;
        reply(fd, "ok\n");
        return;
    }
    char out[4096] = "";
    for (unsigned i = 0; i < bus.station_count; i++) {
        struct sim_servo *s = &servos[i];
        if (only != NULL && s != only) {
            continue;
        }
        if (strcmp(cmd, "supply") == 0) {
            s->plant.p.supply_v = value / 1000.0;
        } else if (strcmp(cmd, "load") == 0) {
            s->plant.load_torque = value;
        } else if (strcmp(cmd, "ambient") == 0) {
            s->thermal.ambient_c = value;
        } else if (strcmp(cmd, "soak") == 0) {
            thermal_soak(&s->thermal, value);
        } else if (strcmp(cmd, "stop") == 0) {
            s->plant.has_stop = !off;
            s->plant.stop_angle = value * M_PI / 180.0;
        } else if (strcmp(cmd, "failerase") == 0) {
            s->flash.fail_erases = s->slot_flash.fail_erases = (uint32_t)value;
        } else if (strcmp(cmd, "failprogram") == 0) {
            s->flash.fail_programs = s->slot_flash.fail_programs = (uint32_t)value;
        } else if (strcmp(cmd, "powercycle") == 0) {
            sim_servo_power_cycle(s);
        } else if (strcmp(cmd, "state") == 0) {
            char one[768];
            state_of(s, one, sizeof one);
            strncat(out, one, sizeof out - strlen(out) - 1);
        } else {
            reply(fd, "error: unknown command (try help)\n");
            return;
        }
    }
    reply(fd, out[0] ? out : "ok\n");
}

static void control_read(struct control_client *c)
{
    char buf[256];
    ssize_t n = read(c->fd, buf, sizeof buf);
    if (n <= 0) {
        close(c->fd);
        c->fd = -1;
        return;
    }
    for (ssize_t i = 0; i < n; i++) {
        if (buf[i] == '\n' || c->used == sizeof c->line - 1) {
            c->line[c->used] = '\0';
            control_command(c->fd, c->line);
            c->used = 0;
        } else {
            c->line[c->used++] = buf[i];
        }
    }
}

int main(int argc, char **argv)
{
    struct options o;
    parse(argc, argv, &o);
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN);
    mkdir(o.state_dir, 0755);

    sim_bus_init(&bus, sim_now_us());
    for (unsigned i = 0; i < o.id_count; i++) {
        if (!sim_servo_start(&servos[i], &bus, i, o.ids[i], o.state_dir, o.supply_v, o.ambient_c)) {
            return 1;
        }
        servos[i].rx_interrupt = o.rx_interrupt;
        sim_bus_attach(&bus, sim_servo_station(&servos[i]));
    }

    int listen_fd = -1;
    int slave_fd = -1;
    int bound = 0;
    char where[128];
    if (o.tcp_port) {
        listen_fd = listen_on(o.tcp_port, &bound);
        snprintf(where, sizeof where, "socket://127.0.0.1:%d", bound);
    } else {
        bus.host_fd = open_pty(o.link, where, sizeof where, &slave_fd);
    }
    int control_bound;
    int control_fd = listen_on(o.control_port, &control_bound);
    struct control_client clients[MAX_CONTROL_CLIENTS];
    for (int i = 0; i < MAX_CONTROL_CLIENTS; i++) {
        clients[i].fd = -1;
    }

    printf("servo_sim: bus %s\n", where);
    if (o.link) {
        printf("servo_sim: link %s\n", o.link);
    }
    printf("servo_sim: control 127.0.0.1:%d\n", control_bound);
    printf("servo_sim: servos");
    for (unsigned i = 0; i < o.id_count; i++) {
        printf(" %u", o.ids[i]);
    }
    printf("\nservo_sim: ready\n");
    fflush(stdout);

    while (!stop_requested) {
        struct pollfd fds[3 + MAX_CONTROL_CLIENTS];
        int nfds = 0;
        int host_slot = -1, listen_slot = -1, control_slot;
        /* A host that writes faster than the line waits (it is not read),
         * as behind its own UART. */
        if (bus.host_fd >= 0) {
            host_slot = nfds;
            short events = sim_bus_room(&bus) >= 512u ? POLLIN : 0;
            fds[nfds++] = (struct pollfd){.fd = bus.host_fd, .events = events};
        } else if (listen_fd >= 0) {
            listen_slot = nfds;
            fds[nfds++] = (struct pollfd){.fd = listen_fd, .events = POLLIN};
        }
        control_slot = nfds;
        fds[nfds++] = (struct pollfd){.fd = control_fd, .events = POLLIN};
        int client_base = nfds;
        for (int i = 0; i < MAX_CONTROL_CLIENTS; i++) {
            fds[nfds++] = (struct pollfd){.fd = clients[i].fd, .events = POLLIN};
        }
        /* Wake often enough for every control tick and bus byte; not at all
         * while the bus clock is behind the wall clock. */
        uint64_t wall = sim_now_us();
        int64_t due = sim_bus_next_due(&bus, wall);
        long wait_us = (due >= 0 && due < SIM_BUS_STEP_US) ? (long)due : SIM_BUS_STEP_US;
        if (sim_bus_step_to(&bus, wall) < wall) {
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
            ssize_t n = read(bus.host_fd, buf, sizeof buf);
            if (n > 0) {
                sim_bus_from_host(&bus, buf, (unsigned)n, bus.now_us);
            } else if (listen_fd >= 0 && (n == 0 || errno != EAGAIN)) {
                close(bus.host_fd); /* the TCP client left: wait for the next */
                bus.host_fd = -1;
            }
        }
        if (listen_slot >= 0 && (fds[listen_slot].revents & POLLIN)) {
            int fd = accept(listen_fd, NULL, NULL);
            if (fd >= 0) {
                int one = 1; /* a UART does not wait to fill packets */
                setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
                fcntl(fd, F_SETFL, O_NONBLOCK);
                bus.host_fd = fd;
            }
        }
        if (fds[control_slot].revents & POLLIN) {
            int fd = accept(control_fd, NULL, NULL);
            for (int i = 0; fd >= 0 && i < MAX_CONTROL_CLIENTS; i++) {
                if (clients[i].fd < 0) {
                    clients[i] = (struct control_client){.fd = fd};
                    fd = -1;
                }
            }
            if (fd >= 0) {
                reply(fd, "error: too many control connections\n");
                close(fd);
            }
        }
        for (int i = 0; i < MAX_CONTROL_CLIENTS; i++) {
            if (clients[i].fd >= 0 && (fds[client_base + i].revents & (POLLIN | POLLHUP))) {
                control_read(&clients[i]);
            }
        }
        uint64_t wall_now = sim_now_us();
        sim_bus_deliver(&bus, sim_bus_step_to(&bus, wall_now));
        if (wall_now - bus.now_us > most_behind_us) {
            most_behind_us = wall_now - bus.now_us;
        }
        for (unsigned i = 0; i < bus.station_count; i++) {
            sim_servo_poll(&servos[i], bus.now_us);
        }
    }
    if (o.link) {
        unlink(o.link);
    }
    printf("servo_sim: stopped (%lu collisions)\n", bus.collisions);
    return 0;
}
