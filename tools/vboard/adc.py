"""The ADC scanning the board's analogue inputs into RAM by DMA.

F1 (RM0008 11): ADON powers it, CAL calibrates (and clears when done),
CONT with SWSTART (EXTSEL = 7, EXTTRIG) converts the regular sequence
(SQR1's L + 1 channels, SQR3/SQR2's order) over and over; with DMA each
result is a request to DMA channel 1.
F0 (RM0360 12): ADCAL calibrates with the ADC off, ADEN turns it on (ADRDY
once ready), ADSTART with CONT converts the channels CHSELR selects in
ascending order; DMAEN (DMACFG: circular) hands each to DMA channel 1.

A scan's results move to memory at the end of each scan time (12.5 cycles
of conversion plus each channel's sampling time, at the ADC clock), one
scan's worth at each slice boundary past it (the scans in between would
read the same models), with the values the models give at that time; none
while the CPU sleeps, the only reader of that memory (the last scan before
it wakes is written as it wakes)."""
from .model import Model

# Sampling times by SMPx code, the same on both parts (RM0008 11.12.4, RM0360 12.12.6).
SAMPLE_CYCLES = (1.5, 7.5, 13.5, 28.5, 41.5, 55.5, 71.5, 239.5)


class Adc(Model):
    """What both parts' ADCs share: a running scan, one scan's results at
    each boundary past its end."""

    def __init__(self, board, periph, adc_hz, dma, channel_value):
        super().__init__(board, periph)
        self.adc_hz, self.dma, self.channel_value = adc_hz, dma, channel_value
        self.running = False
        self.next_scan_s = float("inf")
        self.dma_channel = 1  # RM0008 table 78, RM0360 table 26; the G0's DMAMUX routes its own

    def reset(self) -> None:
        super().reset()
        self.running, self.next_scan_s = False, float("inf")

    def start(self) -> None:
        """The sequence and its timing as set when the conversions start
        (both parts take a new sequence at the next start)."""
        self.running = True
        self.channels, self.period_s = self.sequence(), self.scan_s()
        self.next_scan_s = self.core.now_s() + self.period_s

    def step(self, now_s: float) -> None:
        if not self.running or now_s < self.next_scan_s:
            return
        if self.core.asleep and not self.core.wake_pending():
            return  # only the CPU reads the results: the scan before it wakes is the one it sees
        values = [self.channel_value(channel) for channel in self.channels]
        self.put("DR", values[-1])
        if self.dma_requests():
            self.dma.transfer_many(self.dma_channel, values)
        period = self.period_s
        self.next_scan_s += period * max(1, int((now_s - self.next_scan_s) / period) + 1)


class AdcF1(Adc):
    def __init__(self, board, periph, adc_hz, dma, channel_value):
        super().__init__(board, periph, adc_hz, dma, channel_value)
        self.watch("CR2", self._cr2)

    def _cr2(self, value, old, size):
        on = value & self.bit("CR2", "ADON")
        if value & self.bit("CR2", "CAL"):
            self.core.fix(self.addr("CR2"), value & ~self.bit("CR2", "CAL"))
        if on and value & self.bit("CR2", "SWSTART") and value & self.bit("CR2", "CONT"):
            self.start()
            self.core.fix(self.addr("CR2"), value & ~self.bit("CR2", "SWSTART"))
        if not on:
            self.running = False

    def dma_requests(self) -> bool:
        return bool(self.get("CR2") & self.bit("CR2", "DMA"))

    def sequence(self) -> list:
        count = ((self.get("SQR1") >> 20) & 0xF) + 1
        words = [self.get("SQR3"), self.get("SQR2"), self.get("SQR1")]
        return [(words[i // 6] >> (5 * (i % 6))) & 0x1F for i in range(count)]

    def scan_s(self) -> float:
        smpr = (self.get("SMPR2"), self.get("SMPR1"))
        cycles = sum(SAMPLE_CYCLES[(smpr[c // 10] >> (3 * (c % 10))) & 7] + 12.5 for c in self.sequence())
        return cycles / self.adc_hz()


class AdcF0(Adc):
    def __init__(self, board, periph, adc_hz, dma, channel_value):
        super().__init__(board, periph, adc_hz, dma, channel_value)
        self.watch("CR", self._cr)
        self.watch("ISR", self._isr)

    def _cr(self, value, old, size):
        if value & self.bit("CR", "ADCAL"):
            value &= ~self.bit("CR", "ADCAL")
        if value & self.bit("CR", "ADEN"):
            self.put("ISR", self.get("ISR") | self.bit("ISR", "ADRDY"))
        if value & self.bit("CR", "ADSTART") and self.get("CFGR1") & self.bit("CFGR1", "CONT"):
            self.start()
        self.core.fix(self.addr("CR"), value)

    def _isr(self, value, old, size):
        self.core.fix(self.addr("ISR"), old & ~value)  # write 1 to clear

    def dma_requests(self) -> bool:
        return bool(self.get("CFGR1") & self.bit("CFGR1", "DMAEN"))

    def sequence(self) -> list:
        selected = self.get("CHSELR")
        return [c for c in range(19) if selected >> c & 1]

    def scan_s(self) -> float:
        sample = SAMPLE_CYCLES[self.get("SMPR") & 7]
        return len(self.sequence()) * (sample + 12.5) / self.adc_hz()
