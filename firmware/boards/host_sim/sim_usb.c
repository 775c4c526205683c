#include "sim_usb.h"

#include <stdlib.h>
#include <string.h>

bool sim_usb_parse(const char *text, struct sim_usb *u)
{
    *u = (struct sim_usb){.mode = SIM_USB_IDLE};
    if (strcmp(text, "usb") == 0) {
        return true;
    }
    if (strcmp(text, "raw") == 0) {
        u->mode = SIM_USB_RAW;
        return true;
    }
    long ms = SIM_USB_FTDI_LATENCY_MS;
    if (strncmp(text, "ftdi:", 5) == 0) {
        char *end;
        ms = strtol(text + 5, &end, 10);
        if (text[5] == '\0' || *end != '\0' || ms < 1 || ms > 255) {
            return false;
        }
    } else if (strcmp(text, "ftdi") != 0) {
        return false;
    }
    u->mode = SIM_USB_FTDI;
    u->latency_us = (uint32_t)ms * 1000u;
    return true;
}

void sim_usb_hold(struct sim_usb *u, uint8_t byte, uint64_t at_us, uint32_t baud)
{
    if (u->count == SIM_USB_HELD) {
        u->dropped++;
        return;
    }
    u->held[u->count] = byte;
    u->held_at[u->count] = at_us;
    u->char_us[u->count] = baud ? (10000000u + baud - 1u) / baud : 87u;
    u->count++;
}

static uint64_t frame_at_or_after(uint64_t t)
{
    return (t + SIM_USB_FRAME_US - 1u) / SIM_USB_FRAME_US * SIM_USB_FRAME_US;
}

static unsigned packet_of(const struct sim_usb *u)
{
    return u->mode == SIM_USB_FTDI ? SIM_USB_FTDI_PACKET : SIM_USB_PACKET;
}

/* ftdi: the first time the latency timer runs out at or after t (it runs
 * out every latency_us from its last restart, data or not). */
static uint64_t timer_out_after(const struct sim_usb *u, uint64_t t)
{
    uint64_t out = u->last_packet_us + u->latency_us;
    if (out < t) {
        out += (t - out + u->latency_us - 1u) / u->latency_us * u->latency_us;
    }
    return out;
}

/* When the adapter would hand over, and whether all it holds then goes
 * (else only its full packets). */
static uint64_t next_handover(const struct sim_usb *u, bool *all)
{
    *all = true;
    if (u->count == 0u) {
        return SIM_USB_NONE;
    }
    if (u->mode == SIM_USB_RAW) {
        return u->held_at[0];
    }
    unsigned packet = packet_of(u);
    uint64_t full = u->count >= packet ? frame_at_or_after(u->held_at[packet - 1u]) : SIM_USB_NONE;
    uint64_t flush;
    if (u->mode == SIM_USB_FTDI) {
        flush = timer_out_after(u, u->held_at[0]);
    } else {
        unsigned last = u->count - 1u;
        flush = frame_at_or_after(u->held_at[last] + SIM_USB_IDLE_CHARS * u->char_us[last]);
    }
    *all = flush <= full;
    return *all ? flush : full;
}

uint64_t sim_usb_due(const struct sim_usb *u)
{
    bool all;
    return next_handover(u, &all);
}

unsigned sim_usb_take(struct sim_usb *u, uint64_t now_us, uint8_t *out, unsigned max)
{
    unsigned n = 0;
    bool all;
    uint64_t at = next_handover(u, &all);
    while (at <= now_us && n < max) {
        /* Only what had ended on the wire by then goes. */
        unsigned ready = 0;
        while (ready < u->count && u->held_at[ready] <= at) {
            ready++;
        }
        unsigned go = all ? ready : ready / packet_of(u) * packet_of(u);
        go = go < max - n ? go : max - n;
        memcpy(out + n, u->held, go);
        n += go;
        u->count -= go;
        memmove(u->held, u->held + go, u->count);
        memmove(u->held_at, u->held_at + go, u->count * sizeof u->held_at[0]);
        memmove(u->char_us, u->char_us + go, u->count * sizeof u->char_us[0]);
        if (u->mode == SIM_USB_FTDI) {
            u->last_packet_us = at; /* the timer restarts at every packet */
        }
        if (go == 0u) {
            break;
        }
        at = next_handover(u, &all);
    }
    return n;
}
