#include "sim_options.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage(FILE *out)
{
    fputs("usage: servo_sim [--id N]... [--tcp PORT | --link PATH] [--control PORT]\n"
          "                 [--state DIR] [--supply MV] [--ambient DEGC] [--rx dma|interrupt]\n"
          "                 [--cpu m3|m0] [--plant FILE] [--host-link usb|ftdi[:MS]|raw]\n"
          "                 [--clock wall|paced]\n"
          "Runs the servo firmware on simulated servos sharing one bus.\n"
          "  --id N         a servo with ID N (repeat for more; default 1). An ID given\n"
          "                 again is one more servo at it, as new servos all hold ID 0\n"
          "                 (serial 0x51a0UUNN: NN the ID given, UU the servos given it before)\n"
          "  --tcp PORT     the bus on 127.0.0.1:PORT (pyserial socket://; 0: any free port,\n"
          "                 printed) instead of a pty\n"
          "  --link PATH    also make PATH a symlink to the pty (not with --tcp)\n"
          "  --control PORT fault injection on 127.0.0.1:PORT (default: any free port)\n"
          "  --state DIR    where each servo's flash file lives (default ./sim-state)\n"
          "  --supply MV    supply voltage (default: the plant's, 7400 for the reference)\n"
          "  --ambient DEGC ambient temperature (default 25)\n"
          "  --rx dma|interrupt  how the port receives: DMA into a ring (the reference\n"
          "                 board, default) or a byte per interrupt, which overruns\n"
          "                 while the flash stalls the CPU\n"
          "  --cpu m3|m0    whose time a main-loop pass, a tick and an answer take:\n"
          "                 the reference board's STM32F103 (default) or the STM32F030's\n"
          "  --plant FILE   every servo's motor, gears and heat from a plant file\n"
          "                 (hal/ports/host/plants/*.toml; default: the reference servo's)\n"
          "  --host-link usb|ftdi[:MS]|raw  how the host's USB-serial adapter hands it\n"
          "                 the bytes off the wire: usb (default) a packet once the line\n"
          "                 is quiet for 4 character times, at the next 1 ms USB frame;\n"
          "                 ftdi an FTDI chip's latency timer (MS, default 16); raw every\n"
          "                 byte as it ends on the wire\n"
          "  --clock wall|paced  wall (default): the simulated clock follows the wall\n"
          "                 clock; paced: it runs only while the host waits on it\n"
          "                 (the clock file, sim_clock.h) and stands still between\n"
          "                 its waits (tests whose host paces an experiment)\n"
          "Control commands, one per line, optional servo last: its bus ID as it is now\n"
          "(every servo that holds it), or its serial number (0x51a0UUNN):\n"
          "  supply MV | load NM | payload GCM2 | stop DEG | stop off | magnet DEG | swapleads N |\n"
          "  ampzero COUNTS | forcekt UNMA (item 81 past the servo's check) |\n"
          "  ambient DEGC | soak DEGC |\n"
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

void sim_options_parse(int argc, char **argv, struct sim_options *o)
{
    *o = (struct sim_options){.tcp_port = -1, .state_dir = "sim-state", .supply_v = -1.0, .ambient_c = 25.0,
                              .cpu = sim_cpu_named("m3")};
    plant_model_reference(&o->plant);
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
            /* An ID given again is another servo at it (a new bus of
             * servos at the factory ID 0): its unit tells it apart. */
            uint8_t unit = 0;
            for (unsigned k = 0; k < o->id_count; k++) {
                unit = (uint8_t)(unit + (o->ids[k] == id));
            }
            o->units[o->id_count] = unit;
            o->ids[o->id_count++] = id;
        } else if (strcmp(a, "--tcp") == 0) {
            o->tcp_port = parse_int(v, "--tcp", 0, 65535);
        } else if (strcmp(a, "--control") == 0) {
            o->control_port = parse_int(v, "--control", 1, 65535);
        } else if (strcmp(a, "--link") == 0) {
            o->link = v;
        } else if (strcmp(a, "--clock") == 0) {
            if (strcmp(v, "wall") != 0 && strcmp(v, "paced") != 0) {
                fprintf(stderr, "servo_sim: --clock is wall or paced, not '%s'\n", v);
                exit(2);
            }
            o->paced = strcmp(v, "paced") == 0;
        } else if (strcmp(a, "--host-link") == 0) {
            if (!sim_usb_parse(v, &o->host_link)) {
                fprintf(stderr, "servo_sim: --host-link is usb, ftdi, ftdi:MS (1 to 255) or raw, not '%s'\n", v);
                exit(2);
            }
        } else if (strcmp(a, "--state") == 0) {
            o->state_dir = v;
        } else if (strcmp(a, "--supply") == 0) {
            o->supply_v = parse_int(v, "--supply", 0, 30000) / 1000.0;
        } else if (strcmp(a, "--ambient") == 0) {
            o->ambient_c = parse_int(v, "--ambient", -40, 150);
        } else if (strcmp(a, "--plant") == 0) {
            char err[256];
            if (!plant_model_load(v, &o->plant, err, sizeof err)) {
                fprintf(stderr, "servo_sim: %s\n", err);
                exit(2);
            }
        } else if (strcmp(a, "--cpu") == 0) {
            o->cpu = sim_cpu_named(v);
            if (o->cpu == NULL) {
                fprintf(stderr, "servo_sim: --cpu is m3 or m0, not '%s'\n", v);
                exit(2);
            }
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
    if (o->link != NULL && o->tcp_port >= 0) {
        fprintf(stderr, "servo_sim: --link names a pseudo-terminal, and --tcp makes none: "
                        "give one or the other\n");
        exit(2);
    }
    if (o->supply_v < 0.0) {
        o->supply_v = o->plant.plant.supply_v;
    }
    if (o->id_count == 0) {
        o->ids[o->id_count++] = 1;
    }
}
