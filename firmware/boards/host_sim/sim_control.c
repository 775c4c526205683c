#define _GNU_SOURCE
#include "sim_control.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sim/control_commands.h"
#include "sim_link.h"

/* The control port's commands (protocol/control_port.toml): what each takes. */
struct control_command {
    const char *name;
    bool takes_value; /* a number, checked against lo..hi */
    bool takes_off;   /* the word off instead */
    double lo, hi;    /* what each model can take: a NaN or an infinity would stay in it for good */
    const char *unit;
};

static const struct control_command commands[] = {SIM_CONTROL_COMMANDS};

static const struct control_command *command_named(const char *name)
{
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++) {
        if (strcmp(name, commands[k].name) == 0) {
            return &commands[k];
        }
    }
    return NULL;
}

/* A command's servo: its bus ID as it is now (0..254: every servo that
 * holds it), or its serial number; -1 when the word is neither. */
static long servo_address(const char *word)
{
    char *end = NULL;
    bool hex = word[0] == '0' && (word[1] == 'x' || word[1] == 'X');
    long v = strtol(word, &end, hex ? 16 : 10);
    return end != word && *end == '\0' && v >= 0 && v <= 0xFFFFFFFFL && v != 255 ? v : -1;
}

static bool addressed(const struct sim_servo *s, long address)
{
    return address < 0 || (address <= 254 ? sim_servo_bus_id(s) == address
                                           : sim_servo_serial(s) == (uint32_t)address);
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

static void state_of(const struct sim_control *c, const struct sim_servo *s, char *out, size_t size)
{
    struct motion_angle a;
    motion_read_angle(&s->core.motion, &a);
    snprintf(out, size,
             "id=%u sim_ms=%.3f last_move_ms=%.3f last_sent_ms=%.3f "
             "angle=%.3f velocity=%.2f current=%.3f winding=%.2f case=%.2f ambient=%.1f "
             "supply=%.3f "
             "load=%.3f payload=%.1f stop=%s status=0x%02x reported=%d collisions=%lu garbled=%lu dropped_ticks=%u "
             "most_behind_ms=%.1f baud=%u host_baud=%u baud_mismatches=%lu rx_overruns=%u "
             "rx_lost=%u flash_stall_ms=%.2f saves=%u mode=%s version=0x%04x resets_power=%u "
             "heard_ms=%.3f coasted_ms=%.3f winding_estimate=%.1f serial=0x%08x\n",
             sim_servo_bus_id(s), (double)c->bus->now_us / 1000.0, (double)s->last_execution_us / 1000.0,
             (double)s->last_sent_us / 1000.0, plant_angle_deg(&s->plant),
             s->plant.velocity * 180.0 / M_PI,
             s->plant.current, s->thermal.winding_c, s->thermal.case_c, s->thermal.ambient_c,
             s->plant.p.supply_v,
             s->plant.load_torque, s->plant.payload_inertia * 1e7, s->plant.has_stop ? "on" : "off", s->core.regs.status.status,
             a.multi_turn_decideg, c->bus->collisions, c->bus->garbled, s->core.ticks_dropped,
             (double)*c->most_behind_us / 1000.0, (unsigned)s->baud, (unsigned)c->bus->host_baud,
             c->bus->baud_mismatches, (unsigned)s->rx.overruns, (unsigned)s->core.rx_lost,
             (double)s->flash_stall_us / 1000.0, (unsigned)s->core.store.sequence,
             s->in_bootloader ? "bootloader" : "app", (unsigned)s->core.regs.status.firmware_version,
             s->power_ups, (double)s->heard_us / 1000.0, (double)s->coasted_us / 1000.0,
             (double)s->core.regs.firmware.winding_decic / 10.0, (unsigned)sim_servo_serial(s));
}

/* "hostsend MS HEX": the host's bytes on the wire from simulated time MS
 * on (or at once, if that has passed), as the host's UART would send them.
 * A test times a frame into a window of a few milliseconds this way,
 * which a host process on a loaded PC cannot. */
static void host_send(const struct sim_control *c, int fd, int n, char **words)
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
    sim_bus_from_host(c->bus, data, (unsigned)len, at_us > c->bus->now_us ? at_us : c->bus->now_us);
    reply(fd, "ok\n");
}

/* The wire's latest spans, oldest first (sim_bus.h). */
static void wire_log(const struct sim_control *c, int fd, const char *count)
{
    const struct sim_bus *b = c->bus;
    unsigned long want = count != NULL ? strtoul(count, NULL, 10) : 64u;
    unsigned long kept = b->span_count < SIM_BUS_SPANS ? b->span_count : SIM_BUS_SPANS;
    want = want < kept ? want : kept;
    for (unsigned long i = b->span_count - want; i < b->span_count; i++) {
        const struct sim_bus_span *s = &b->spans[i % SIM_BUS_SPANS];
        char line[96];
        if (s->sender == SIM_HOST) {
            snprintf(line, sizeof line, "%llu %llu %u host\n", (unsigned long long)s->start_us,
                     (unsigned long long)s->end_us, (unsigned)s->bytes);
        } else {
            snprintf(line, sizeof line, "%llu %llu %u %u\n", (unsigned long long)s->start_us,
                     (unsigned long long)s->end_us, (unsigned)s->bytes,
                     (unsigned)sim_servo_bus_id(&c->servos[s->sender]));
        }
        reply(fd, line);
    }
    reply(fd, "end\n");
}

/* One control line: "command [value] [servo id]". */
static void control_command(const struct sim_control *c, int fd, char *line)
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
        snprintf(out, sizeof out, "sim_ms=%.3f behind_ms=%.1f\n", (double)c->bus->now_us / 1000.0,
                 (double)(sim_now_us() - c->bus->now_us) / 1000.0);
        reply(fd, out);
        return;
    }
    if (strcmp(cmd, "wire") == 0) {
        wire_log(c, fd, n > 1 ? words[1] : NULL);
        return;
    }
    if (strcmp(cmd, "hostsend") == 0) {
        host_send(c, fd, n, words);
        return;
    }
    if (strcmp(cmd, "help") == 0) {
        reply(fd, SIM_CONTROL_HELP);
        return;
    }
    const struct control_command *command = command_named(cmd);
    if (command == NULL) {
        reply(fd, "error: unknown command (try help)\n");
        return;
    }
    bool takes_value = command->takes_value;
    int id_word = takes_value ? 2 : 1;
    long only = -1; /* every servo */
    if (n > id_word) {
        only = servo_address(words[id_word]);
        unsigned found = 0;
        for (unsigned i = 0; only >= 0 && i < c->bus->station_count; i++) {
            found += addressed(&c->servos[i], only);
        }
        if (found == 0u) {
            reply(fd, "error: no servo holds that ID or serial number\n");
            return;
        }
    }
    if (takes_value && n < 2) {
        reply(fd, "error: missing value\n");
        return;
    }
    char *end = NULL;
    double value = takes_value ? strtod(words[1], &end) : 0.0;
    bool off = takes_value && strcmp(words[1], "off") == 0;
    if (off && !command->takes_off) {
        reply(fd, "error: only stop takes off\n");
        return;
    }
    if (takes_value && !off && (end == words[1] || *end != '\0')) {
        reply(fd, "error: the value must be a number\n");
        return;
    }
    if (takes_value && !off && !(value >= command->lo && value <= command->hi)) {
        char msg[128];
        snprintf(msg, sizeof msg, "error: %s takes %g to %g %s, not %s\n", cmd, command->lo,
                 command->hi, command->unit, words[1]);
        reply(fd, msg);
        return;
    }
    if (strcmp(cmd, "hostbaud") == 0) {
        c->bus->host_baud = (uint32_t)value;
        reply(fd, "ok\n");
        return;
    }
    /* Who is addressed is decided before any servo is touched: a power
     * cycle does not move another servo into the set. */
    bool chosen[SIM_MAX_SERVOS];
    for (unsigned i = 0; i < c->bus->station_count; i++) {
        chosen[i] = addressed(&c->servos[i], only);
    }
    for (unsigned i = 0; i < c->bus->station_count; i++) {
        struct sim_servo *s = &c->servos[i];
        if (!chosen[i]) {
            continue;
        }
        if (strcmp(cmd, "supply") == 0) {
            s->plant.p.supply_v = value / 1000.0;
        } else if (strcmp(cmd, "load") == 0) {
            s->plant.load_torque = value;
        } else if (strcmp(cmd, "payload") == 0) {
            s->plant.payload_inertia = value * 1e-7; /* g cm^2 to kg m^2 */
        } else if (strcmp(cmd, "magnet") == 0) {
            s->magnet_counts = (uint16_t)((long)floor(value / 360.0 * 4096.0 + 0.5) & 4095);
        } else if (strcmp(cmd, "swapleads") == 0) {
            s->leads_swapped = value != 0.0;
        } else if (strcmp(cmd, "ampzero") == 0) {
            s->amp_zero_counts = (uint16_t)value;
        } else if (strcmp(cmd, "forcekt") == 0) { /* past drive_items_stable */
            s->core.regs.user.kt_un_m_per_a = (uint16_t)value;
            motion_drive_train_changed(&s->core.motion);
        } else if (strcmp(cmd, "ambient") == 0) {
            s->thermal.ambient_c = value;
        } else if (strcmp(cmd, "soak") == 0) {
            thermal_soak(&s->thermal, value);
        } else if (strcmp(cmd, "stop") == 0) {
            s->plant.has_stop = !off;
            s->plant.stop_angle = value * M_PI / 180.0;
        } else if (strcmp(cmd, "failerase") == 0) {
            s->flash.fail_erases = s->slot_flash.fail_erases = s->fault_flash.fail_erases = (uint32_t)value;
        } else if (strcmp(cmd, "failprogram") == 0) {
            s->flash.fail_programs = s->slot_flash.fail_programs = s->fault_flash.fail_programs =
                (uint32_t)value;
        } else if (strcmp(cmd, "unplug") == 0) {
            c->bus->stations[s->index].unplugged = value != 0.0;
        } else if (strcmp(cmd, "powercycle") == 0) {
            sim_servo_power_cycle(s);
        } else { /* state: a line a servo, however many (no buffer to outgrow) */
            char one[768];
            state_of(c, s, one, sizeof one);
            reply(fd, one);
        }
    }
    if (strcmp(cmd, "state") != 0) {
        reply(fd, "ok\n");
    }
}

static void control_read(const struct sim_control *ctl, struct sim_control_client *c)
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
            control_command(ctl, c->fd, c->line);
            c->used = 0;
        } else {
            c->line[c->used++] = buf[i];
        }
    }
}

void sim_control_open(struct sim_control *c, int port, struct sim_bus *bus,
                      struct sim_servo *servos, const uint64_t *most_behind_us)
{
    *c = (struct sim_control){.bus = bus, .servos = servos, .most_behind_us = most_behind_us};
    c->listen_fd = sim_listen_on(port, &c->port);
    for (int i = 0; i < SIM_CONTROL_CLIENTS; i++) {
        c->clients[i].fd = -1;
    }
}

void sim_control_fds(const struct sim_control *c, struct pollfd fds[SIM_CONTROL_FDS])
{
    fds[0] = (struct pollfd){.fd = c->listen_fd, .events = POLLIN};
    for (int i = 0; i < SIM_CONTROL_CLIENTS; i++) {
        fds[1 + i] = (struct pollfd){.fd = c->clients[i].fd, .events = POLLIN};
    }
}

void sim_control_serve(struct sim_control *c, const struct pollfd fds[SIM_CONTROL_FDS])
{
    if (fds[0].revents & POLLIN) {
        int fd = accept(c->listen_fd, NULL, NULL);
        for (int i = 0; fd >= 0 && i < SIM_CONTROL_CLIENTS; i++) {
            if (c->clients[i].fd < 0) {
                c->clients[i] = (struct sim_control_client){.fd = fd};
                fd = -1;
            }
        }
        if (fd >= 0) {
            reply(fd, "error: too many control connections\n");
            close(fd);
        }
    }
    for (int i = 0; i < SIM_CONTROL_CLIENTS; i++) {
        if (c->clients[i].fd >= 0 && (fds[1 + i].revents & (POLLIN | POLLHUP))) {
            control_read(c, &c->clients[i]);
        }
    }
}
