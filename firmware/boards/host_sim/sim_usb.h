/* The host's USB-serial adapter: how the bytes that end on the wire reach
 * the host program (pty or TCP). Every real host talks to the bus through
 * a USB-UART bridge, which hands received bytes over in USB packets, not
 * one by one as they end on the wire. Modes (servo_sim --host-link):
 *
 *   usb      (default) a bridge that ends a packet when the line has been
 *            quiet for SIM_USB_IDLE_CHARS character times, or when it holds
 *            a full packet (SIM_USB_PACKET bytes); the host collects packets
 *            at the start of each USB full-speed frame (SIM_USB_FRAME_US).
 *   ftdi[:MS] an FTDI FT232R/FT232BM: it hands over what it holds when its
 *            latency timer runs out (MS, 1..255, default 16), the timer
 *            restarting at every packet, empty or not; or at once when it
 *            holds 62 bytes (a 64-byte packet less its 2 status bytes).
 *   raw      every byte as it ends on the wire (a test of the host's own
 *            reader against the worst case).
 *
 * Where the figures come from (docs/simulator.md, "The host's adapter"):
 *   1 ms frame: USB 2.0 specification, 8.4.3.1 (a full-speed SOF every 1.00 ms).
 *   64 B packet: USB 2.0, 5.8.3 (a full-speed bulk endpoint's largest packet).
 *   16 ms latency timer, 1-255 ms, 62 + 2 status bytes: FTDI AN232B-04,
 *   "Small Amounts of Data and End of Buffer Conditions" and "Adjusting the
 *   Receive Buffer Latency Timer"; Linux's ftdi_sio keeps the chip's 16 ms.
 *   4 character times of quiet: the receive timeout of the 16550 UART's FIFO
 *   (the CH340 and CP210x do not publish theirs; Linux's ch341 driver sets
 *   the CH340's bit that stops it waiting for a full 32-byte packet). */
#ifndef SIM_USB_H
#define SIM_USB_H

#include <stdbool.h>
#include <stdint.h>

#define SIM_USB_FRAME_US 1000u
#define SIM_USB_PACKET 64u
#define SIM_USB_FTDI_PACKET 62u
#define SIM_USB_IDLE_CHARS 4u
#define SIM_USB_FTDI_LATENCY_MS 16u
#define SIM_USB_HELD 4096u
#define SIM_USB_NONE UINT64_MAX

enum sim_usb_mode { SIM_USB_IDLE, SIM_USB_FTDI, SIM_USB_RAW };

struct sim_usb {
    enum sim_usb_mode mode;
    uint32_t latency_us;   /* ftdi: the latency timer */
    uint8_t held[SIM_USB_HELD];
    uint64_t held_at[SIM_USB_HELD]; /* when each byte's stop bit ended */
    uint32_t char_us[SIM_USB_HELD]; /* its character time (10 bits) */
    unsigned count;
    uint64_t last_packet_us; /* ftdi: when the timer last restarted */
    unsigned long dropped;   /* more than SIM_USB_HELD held: the host does not read */
};

/* Parses "usb", "ftdi", "ftdi:MS" or "raw"; false if it is none of them. */
bool sim_usb_parse(const char *text, struct sim_usb *u);
/* A byte has ended on the wire at at_us, at baud. */
void sim_usb_hold(struct sim_usb *u, uint8_t byte, uint64_t at_us, uint32_t baud);
/* When the adapter next hands bytes over (SIM_USB_NONE: it holds none). */
uint64_t sim_usb_due(const struct sim_usb *u);
/* The bytes handed over by now_us, into out (at most max); their count. */
unsigned sim_usb_take(struct sim_usb *u, uint64_t now_us, uint8_t *out, unsigned max);

#endif
