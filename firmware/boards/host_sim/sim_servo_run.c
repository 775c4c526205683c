/* A simulated servo's CPU in bus time (sim_servo.h): a byte's arrival as
 * its port takes it, when the next main-loop pass runs, the pass and what
 * it costs on the target; sim_servo.c builds the servo and its boot. */
#include "sim_servo.h"

#include <stddef.h>

static void receive(void *ctx, uint8_t byte, uint64_t at_us)
{
    struct sim_servo *s = ctx;
    /* A byte's interrupt ends a sleep; by DMA, the USART's IDLE does, a
     * byte time after the last byte (RM0008 27.3.3). */
    s->asleep = s->asleep && !s->rx_interrupt;
    s->idle_at_us = at_us + (10000000u + s->baud - 1u) / s->baud;
    if (s->polling && s->landed_us == 0u) {
        s->landed_us = at_us;
    }
    if (s->rx_interrupt) {
        if (at_us < s->cpu_free_us) {
            if (s->uart_full) {
                s->rx.overruns++; /* the receive interrupt could not run */
            } else {
                s->uart_full = true;
                s->uart_held = byte;
                s->uart_held_at_us = (uint32_t)at_us;
            }
            return;
        }
        if (s->uart_full) {
            s->uart_full = false;
            hal_rx_ring_put(&s->rx, s->uart_held, s->uart_held_at_us);
        }
    }
    if (s->rx_interrupt) {
        servo_on_rx_byte(&s->core, byte, (uint32_t)at_us);
        return;
    }
    /* The reference board's DMA writes each byte whatever the CPU does; a
     * ring the main loop has not emptied (a page erase stalls it 40 ms) is
     * written over, oldest bytes first (RM0008 13.3.6, circular mode), and
     * the main loop counts what it lost by the write counter. */
    uint32_t w = s->rx.written;
    s->rx.data[w & s->rx.mask] = byte;
    s->rx.written = w + 1u;
    s->rx.heard_us = (uint32_t)at_us;
}

/* What this pass's flash work stalls the CPU for (sim_flash.h). */
static uint32_t flash_stall_us(const struct sim_servo *s)
{
    return s->flash.stall_us + s->slot_flash.stall_us + s->fault_flash.stall_us;
}

/* The bus time a 32-bit firmware time falls at, not before now. */
static uint64_t bus_time_of(uint64_t now_us, uint32_t at_us)
{
    int32_t ahead = (int32_t)(at_us - (uint32_t)now_us);
    return ahead > 0 ? now_us + (uint64_t)ahead : now_us;
}

uint64_t sim_servo_wake_at(const struct sim_servo *s)
{
    uint64_t now = s->bus->now_us;
    uint64_t free = s->cpu_free_us > s->next_pass_us ? s->cpu_free_us : s->next_pass_us;
    if (!s->asleep && !s->polling) {
        return free > now ? free : now;
    }
    uint64_t wake = bus_time_of(now, s->core.tick_due_us);
    if (s->landed_us != 0u) {
        /* A polling loop finds a byte half a pass after it lands, on average. */
        uint64_t found = s->landed_us + (s->cpu->pass_ns / 2u + 500u) / 1000u;
        wake = found < wake ? found : wake;
    }
    if (s->idle_at_us != 0u && s->idle_at_us < wake) {
        wake = s->idle_at_us;
    }
    if (s->core.tx.sending && s->tx_done_us < wake) {
        wake = s->tx_done_us; /* the transmission's end */
    }
    return wake > free ? wake : free;
}

/* A pass that framed a Sync Monitor (this servo listed first) and sent
 * its answer: on either CPU the answer leaves sync_answer_ns into the
 * pass; the M0 builds the rest of it behind its first bytes, the M3
 * before. */
static bool sent_sync_answer(const struct sim_servo *s, uint32_t frames_before)
{
    const struct servo *c = &s->core;
    const struct rx_frame *f = &c->rx.slots[(c->rx.tail + FRAME_QUEUE_SLOTS - 1u) % FRAME_QUEUE_SLOTS];
    return s->tx_data != NULL && c->rx.stats.frames == frames_before + 1u && f->code == PKT_SYNC_COMMAND;
}

/* What a pass's requests cost beyond the pass, and when in it the answer
 * it sends leaves (*send_ns). */
static uint64_t request_cost_ns(const struct sim_servo *s, uint32_t heard_before,
                                uint32_t frames_before, uint64_t *send_ns)
{
    const struct servo *c = &s->core;
    bool heard = c->dispatcher.heard != heard_before;
    bool framed = c->rx.stats.frames != frames_before;
    uint64_t cost = (heard || framed) * (uint64_t)s->cpu->answer_ns;
    *send_ns = cost;
    if (sent_sync_answer(s, frames_before)) {
        *send_ns = s->cpu->sync_answer_ns;
        cost = s->cpu->sends_ahead ? s->cpu->answer_ns : s->cpu->sync_answer_ns;
    }
    return cost;
}

/* One main-loop pass at now_us, then what it cost on the target's CPU:
 * the answer it started leaves at its end, and the next pass starts
 * there. */
static void run_pass(struct sim_servo *s, uint64_t now_us)
{
    uint32_t ticks_before = s->core.next_tick_us;
    uint32_t heard_before = s->core.dispatcher.heard;
    uint32_t frames_before = s->core.rx.stats.frames;
    bool in_app = !s->in_bootloader; /* the core's counters are this pass's */
    s->landed_us = 0;
    if (!s->in_bootloader || !sim_servo_boot_poll(s)) {
        servo_poll(&s->core);
    }
    uint64_t cost_ns = s->cpu->pass_ns;
    uint64_t send_ns = 0; /* when in the pass its answer leaves */
    bool timed = in_app && !s->in_bootloader;
    if (timed) {
        cost_ns += (uint64_t)((s->core.next_tick_us - ticks_before) / CONTROL_TICK_US) * s->cpu->tick_ns;
        uint64_t answer_ns = 0;
        uint64_t request_ns = request_cost_ns(s, heard_before, frames_before, &answer_ns);
        send_ns = cost_ns + answer_ns;
        cost_ns += request_ns;
    }
    uint64_t cost_us = (cost_ns + 500u) / 1000u;
    uint64_t send_us = timed ? (send_ns + 500u) / 1000u : cost_us;
    s->next_pass_us = now_us + (cost_us != 0u ? cost_us : 1u);
    if (s->tx_data != NULL) {
        /* After the flash work of this pass too: a flash step stalls the
         * CPU (RM0008 3.3.3), so an answer to a write that programmed
         * flash leaves once the programming is done. */
        uint64_t at = now_us + send_us + flash_stall_us(s);
        s->last_sent_us = at;
        s->tx_done_us = sim_bus_send(s->bus, s->index, s->tx_data, s->tx_len, s->baud, at);
        s->tx_data = NULL;
    }
    s->asleep = !s->in_bootloader && servo_may_sleep(&s->core);
    s->polling = !s->in_bootloader && !s->asleep && servo_awaits_bytes(&s->core);
    if (s->idle_at_us <= now_us) {
        s->idle_at_us = 0;
    }
}

void sim_servo_poll(struct sim_servo *s, uint64_t now_us)
{
    if (now_us < sim_servo_wake_at(s)) {
        return;
    }
    if (s->uart_full) { /* the interrupt runs as soon as the CPU does */
        s->uart_full = false;
        hal_rx_ring_put(&s->rx, s->uart_held, s->uart_held_at_us);
    }
    run_pass(s, now_us);
    if (s->core.dispatcher.heard != s->heard_seen) {
        s->heard_seen = s->core.dispatcher.heard;
        s->heard_us = now_us;
    }
    bool executing = !s->in_bootloader && (s->core.regs.status.status & STATUS_EXECUTING) != 0u;
    if (executing && !s->executing) {
        s->executing_from_us = now_us;
    } else if (!executing && s->executing) {
        s->last_execution_us = now_us - s->executing_from_us;
    }
    s->executing = executing;
    uint32_t stall = flash_stall_us(s);
    if (stall != 0u) {
        s->cpu_free_us = now_us + stall;
        s->flash_stall_us += stall;
        s->flash.stall_us = 0;
        s->slot_flash.stall_us = 0;
        s->fault_flash.stall_us = 0;
    }
}

struct sim_station sim_servo_station(struct sim_servo *s)
{
    return (struct sim_station){.ctx = s, .baud = &s->baud, .receive = receive,
                                .log_id = s->cmdline_id};
}
