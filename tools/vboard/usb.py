"""The host's USB-serial adapter, in simulated time: how the bytes that end
on the wire reach the host program. The same model, modes and figures as
servo_sim's (firmware/boards/host_sim/sim_usb.h, docs/simulator.md):

  usb        (default) a packet once the line has been quiet for 4
             character times (the 16550 UART's receive timeout), or once it
             holds 64 bytes (a full-speed bulk packet, USB 2.0 5.8.3), handed
             over at the start of the next 1 ms full-speed frame (USB 2.0 8.4.3).
  ftdi[:MS]  an FTDI chip: what it holds goes when its latency timer runs out
             (MS, 1..255, default 16: FTDI AN232B-04), the timer restarting at
             every packet; or at once when it holds 62 bytes (64 less 2 status).
  raw        every byte as it ends on the wire."""
FRAME_US = 1000
PACKET = 64
FTDI_PACKET = 62
IDLE_CHARS = 4
FTDI_LATENCY_MS = 16
FRAME_BITS = 10
MODES = "usb, ftdi, ftdi:MS (1 to 255) or raw"
NONE = float("inf")


def _frame_at_or_after(us: int) -> int:
    return -(-us // FRAME_US) * FRAME_US


class Adapter:
    """Times in whole microseconds from hold() on, as servo_sim's clock
    (sim_usb.c): the same hand-overs, and none before the byte it waits for."""

    def __init__(self, mode: str = "usb"):
        self.latency_us = None
        if mode == "usb" or mode == "raw":
            self.mode = mode
        elif mode == "ftdi" or mode.startswith("ftdi:"):
            ms = mode[5:] if mode.startswith("ftdi:") else str(FTDI_LATENCY_MS)
            if not ms.isdigit() or not 1 <= int(ms) <= 255:
                raise ValueError(f"--host-link is {MODES}, not '{mode}'")
            self.mode, self.latency_us = "ftdi", int(ms) * 1000
        else:
            raise ValueError(f"--host-link is {MODES}, not '{mode}'")
        self.held = []             # (end_us, byte, char_us), oldest first
        self.last_packet_us = 0    # ftdi: when the latency timer last restarted

    @property
    def last_packet_s(self) -> float:
        return self.last_packet_us / 1e6

    def hold(self, byte: int, end_s: float, baud: int) -> None:
        char_us = -(-FRAME_BITS * 1_000_000 // baud) if baud else 87  # rounded up, as sim_usb_hold
        self.held.append((round(end_s * 1e6), byte, char_us))

    def _packet(self) -> int:
        return FTDI_PACKET if self.mode == "ftdi" else PACKET

    def _timer_out_after(self, t_us: int) -> int:
        out = self.last_packet_us + self.latency_us
        if out < t_us:
            out += -(-(t_us - out) // self.latency_us) * self.latency_us
        return out

    def _next(self):
        """(when it next hands over, us, whether all it holds goes then)."""
        if not self.held:
            return NONE, True
        if self.mode == "raw":
            return self.held[0][0], True
        packet = self._packet()
        full = _frame_at_or_after(self.held[packet - 1][0]) if len(self.held) >= packet else NONE
        if self.mode == "ftdi":
            flush = self._timer_out_after(self.held[0][0])
        else:
            end_us, _, char_us = self.held[-1]
            flush = _frame_at_or_after(end_us + IDLE_CHARS * char_us)
        return (flush, True) if flush <= full else (full, False)

    def due_s(self) -> float:
        return self._next()[0] / 1e6

    def take(self, now_s: float):
        """The bytes handed over by now_s, and when the host had the last
        of them (None: none)."""
        now_us = round(now_s * 1e6)
        out, at_last = bytearray(), None
        at, everything = self._next()
        while at <= now_us:
            ready = sum(1 for end_us, _, _ in self.held if end_us <= at)
            go = ready if everything else ready // self._packet() * self._packet()
            out += bytes(b for _, b, _ in self.held[:go])
            if go:
                at_last = max(at, self.held[go - 1][0]) / 1e6
            del self.held[:go]
            if self.mode == "ftdi":
                self.last_packet_us = at  # the timer restarts at every packet
            if go == 0:
                break
            at, everything = self._next()
        return bytes(out), at_last
