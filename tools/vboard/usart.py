"""A USART in single-wire half-duplex (RM0008 27, RM0360 23), on the bus.

Transmit: a byte written to the data register goes to the shift register
when it is free (TXE stays set), else waits there (TXE clear); each byte is
10 bit times on the wire at the rate BRR sets (PCLK / BRR, 16x
oversampling, 8N1); TC sets when the last has left. With DMAT the transmit
DMA channel fills the data register whenever it is empty. Only with TE, and
only when the TX pin is the USART's (the board's pin check), does it reach
the wire.

Receive: a byte on the wire reaches the USART if UE and RE are set, at its
rate (3 % off: a framing error, the byte lost). With DMAR the DMA channel
takes it (a circular channel overwrites what the CPU has not taken); else
it waits in the data register with RXNE, and the next one overruns it (ORE;
the F0's OVRDIS keeps the old byte, as here). In half-duplex mode the
receiver hears the USART's own bytes unless the firmware clears RE.

IDLE sets when the line has stayed quiet for a frame after a received
byte, once per burst (RM0008 27.6.1, RM0360 23.8.1), cleared on the F1 by
reading DR after SR (here: by any read of DR by the CPU) and on the F0 by
ICR's IDLECF.

The interrupt line is level: TXEIE with TXE, TCIE with TC, RXNEIE with RXNE
or ORE, IDLEIE with IDLE. It rises when a flag or an enable is set, which
is when the model sets one or the CPU writes CR1; the core takes it again
after a handler that left it high. Registers by the part: the F1's SR/DR (status cleared by writing 0
to RXNE/TC) and the F0's ISR/ICR/RDR/TDR."""
from unicorn import UC_HOOK_MEM_READ

from .model import Model

FRAME_BITS = 10
MISMATCH = 0.03


class Usart(Model):
    def __init__(self, board, periph, pclk_hz, irq: int, dma, dma_channel: int, tx_dma_channel: int, tx_pin_ok):
        super().__init__(board, periph)
        self.v2 = "ISR" in periph.registers
        self.status = "ISR" if self.v2 else "SR"
        self.pclk_hz, self.irq, self.dma, self.dma_channel = pclk_hz, irq, dma, dma_channel
        self.tx_dma_channel = tx_dma_channel
        dma.on_enable[tx_dma_channel] = self.pull
        self.tx_pin_ok = tx_pin_ok
        self.bus_station = None
        self.shift_until_s = 0.0
        self.shifting = False
        self.tdr = None
        self.rx_bytes = self.rx_lost = self.overruns = self.framing_errors = 0
        self.idle_at_s = None     # when IDLE sets unless another byte comes first
        self.re_since_s = 0.0     # when the receiver was last turned on
        self.begun_deaf = 0       # bytes that began before it was: not heard
        self.watch("TDR" if self.v2 else "DR", self._write_data)
        self.watch("CR1", self._write_cr1)
        self.watch("ICR" if self.v2 else "SR", self._clear_flags)
        s = self.status
        self.RXNE, self.TC, self.TXE = self.bit(s, "RXNE"), self.bit(s, "TC"), self.bit(s, "TXE")
        self.ORE, self.FE, self.IDLE = self.bit(s, "ORE"), self.bit(s, "FE"), self.bit(s, "IDLE")
        self.DMAT, self.DMAR = self.bit("CR3", "DMAT"), self.bit("CR3", "DMAR")
        self.UE_RE = self.bit("CR1", "UE") | self.bit("CR1", "RE")
        self.UE_TE = self.bit("CR1", "UE") | self.bit("CR1", "TE")
        self.TXEIE, self.TCIE = self.bit("CR1", "TXEIE"), self.bit("CR1", "TCIE")
        self.RXNEIE, self.IDLEIE = self.bit("CR1", "RXNEIE"), self.bit("CR1", "IDLEIE")
        self.i_sr, self.i_cr1, self.i_cr3, self.i_brr = self.i[s], self.i["CR1"], self.i["CR3"], self.i["BRR"]
        self._baud_for = None     # (BRR, the board's clock setting) the cached baud rate is for
        self._baud = 0
        if not self.v2:  # the F1's DR read clears IDLE: one narrow read hook
            dr = self.addr("DR")
            self.dr_read_hook = self.core.uc.hook_add(UC_HOOK_MEM_READ, self._dr_read,
                                                      begin=dr, end=dr + 3)

    def _dr_read(self, *_) -> None:
        self.core.count.hooks += 1  # a pass that reads it is no idle pass (idle_skip.py)
        self._set(self.IDLE, False)

    def reset(self) -> None:
        super().reset()
        self.shifting, self.tdr = False, None
        self.idle_at_s = None

    def baud(self) -> int:
        """PCLK / BRR: worked out again only when BRR or the clocks change."""
        key = (self.w[self.i_brr] & 0xFFFF, self.board.clock_setting)
        if key != self._baud_for:
            brr = key[0]
            self._baud_for, self._baud = key, (self.pclk_hz() // brr if brr else 0)
        return self._baud

    def _set(self, flag: int, on: bool) -> None:
        w, i = self.w, self.i_sr
        if on:
            w[i] |= flag
            if self._interrupt_due(w[i], w[self.i_cr1]):
                self.core.assert_irq(self.irq, self.line)
        else:
            w[i] &= ~flag

    def _write_data(self, value, old, size):
        if self.w[self.i_cr1] & self.UE_TE != self.UE_TE:
            return
        if not self.shifting:
            self._start(value & 0xFF)
        else:
            self.tdr = value & 0xFF
            self._set(self.TXE, False)

    def _start(self, byte: int) -> None:
        now = self.core.now_s()
        baud = self.baud()
        self.shifting = True
        self.shift_until_s = now + FRAME_BITS / max(baud, 1)
        self._set(self.TC, False)
        self._set(self.TXE, True)
        if self.tx_pin_ok() and baud:
            self.board.bus.send(self.bus_station, byte, baud, now)
        self.core.new_event()
        self.pull()

    def pull(self) -> None:
        """With DMAT, an empty data register asks the transmit channel for
        the next byte (RM0008 27.3.13, RM0360 23.5.15)."""
        if self.tdr is None and self.w[self.i_cr3] & self.DMAT:
            byte = self.dma.take(self.tx_dma_channel)
            if byte is not None:
                self._write_data(byte, 0, 1)

    def _write_cr1(self, value, old, size):
        """An interrupt enabled while its flag is set fires at once (the
        driver starts a transmission by setting TXEIE): the CPU stops after
        the store and takes it."""
        re = self.bit("CR1", "RE")
        if value & re and not old & re:
            self.re_since_s = self.core.now_s()
        if self._interrupt_due(self.w[self.i_sr], value):
            self.core.assert_irq(self.irq, self.line)
            self.core.defer(lambda: None)

    def line(self) -> bool:
        """The USART's interrupt line, as its flags and enables set it now."""
        return self._interrupt_due(self.w[self.i_sr], self.w[self.i_cr1])

    def _interrupt_due(self, sr: int, cr1: int) -> bool:
        return bool((cr1 & self.TXEIE and sr & self.TXE) or
                    (cr1 & self.TCIE and sr & self.TC) or
                    (cr1 & self.RXNEIE and sr & (self.RXNE | self.ORE)) or
                    (cr1 & self.IDLEIE and sr & self.IDLE))

    def _clear_flags(self, value, old, size):
        sr = self.get(self.status)
        if self.v2:  # ICR: write 1 to clear (PECF, FECF, NCF, ORECF, IDLECF, TCCF)
            for name, flag in (("ORECF", self.ORE), ("FECF", self.FE), ("TCCF", self.TC), ("IDLECF", self.IDLE)):
                if value & self.bit("ICR", name):
                    sr &= ~flag
            self.put(self.status, sr)
            self.core.fix(self.addr("ICR"), 0)
        else:  # SR: RXNE and TC clear when written 0 (rc_w0)
            keep = value | ~(self.RXNE | self.TC)
            self.core.fix(self.addr("SR"), old & keep)

    def receive(self, byte: int, baud: int) -> None:
        """A byte off the wire, at the time it ends; heard only by a
        receiver that was on when it began (the line turned around at the
        last stop bit of the USART's own answer does not hear that byte)."""
        w = self.w
        if w[self.i_cr1] & self.UE_RE != self.UE_RE:
            return
        if self.re_since_s > self.core.time_s - FRAME_BITS / baud:
            self.begun_deaf += 1
            return
        own = self.baud()
        if not own or abs(own - baud) > MISMATCH * own:
            self.framing_errors += 1
            self._set(self.FE, True)
            return
        self.rx_bytes += 1
        # A whole idle frame after this stop bit: a byte that starts right
        # at its end (back to back) is no idle line, so half a bit more.
        self.idle_at_s = self.core.time_s + (FRAME_BITS + 0.5) / own
        if w[self.i_cr3] & self.DMAR and self.dma.enabled(self.dma_channel):
            self.dma.transfer(self.dma_channel, byte)
            return
        if w[self.i_sr] & self.RXNE:
            self.overruns += 1
            self._set(self.ORE, True)
            return
        self.put("RDR" if self.v2 else "DR", byte)
        self._set(self.RXNE, True)

    def step(self, now_s: float) -> None:
        if self.idle_at_s is not None and now_s >= self.idle_at_s:
            self.idle_at_s = None
            self._set(self.IDLE, True)
        if self.shifting and now_s >= self.shift_until_s:
            self.shifting = False
            if self.tdr is not None:
                byte, self.tdr = self.tdr, None
                self._start(byte)
            else:
                self._set(self.TC, True)

    def next_event_s(self, now_s: float) -> float:
        idle = float("inf") if self.idle_at_s is None else self.idle_at_s
        return min(self.shift_until_s if self.shifting else float("inf"), idle)
