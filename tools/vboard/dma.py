"""The DMA controller's channels (RM0008 13, RM0360 10; the same registers
on both parts): a peripheral's request moves one item to memory (or from
it), the counter counts down, half and full transfer set their flags and,
where enabled, raise the channel's interrupt; a circular channel reloads
its counter and starts over, overwriting what the CPU has not yet taken."""
from .model import Model


class Dma(Model):
    def __init__(self, board, periph, irqs: dict):
        super().__init__(board, periph)
        self.irqs = irqs  # channel -> IRQ line
        self.reload = {}
        self.on_enable = {}  # channel -> the peripheral whose requests it serves: its pull()
        self.channels = [n for n in range(1, 8) if f"CCR{n}" in periph.registers]
        # channel -> the indices of its CCR, CNDTR, CPAR and CMAR
        self.regs = {n: tuple(self.i[f"{r}{n}"] for r in ("CCR", "CNDTR", "CPAR", "CMAR")) for n in self.channels}
        self.i_isr = self.i["ISR"]
        for n in self.channels:
            self.watch(f"CCR{n}", self._ccr(n))
        self.watch("IFCR", self._ifcr)

    def reset(self) -> None:
        super().reset()
        self.reload = {}

    def _ccr(self, n: int):
        def handler(value, old, size):
            if value & 1 and not old & 1:  # EN: the counter's start value is its reload
                self.reload[n] = self.w[self.regs[n][1]] & 0xFFFF
                if n in self.on_enable:  # a request already waiting is served at once
                    self.core.defer(self.on_enable[n])
        return handler

    def _ifcr(self, value, old, size):
        self.put("ISR", self.get("ISR") & ~value)
        self.core.fix(self.addr("IFCR"), 0)

    def enabled(self, n: int) -> bool:
        """Channel n is on (0, or one the part lacks: a request routed
        nowhere, the G0's DMAMUX before it is set)."""
        return n in self.regs and bool(self.w[self.regs[n][0]] & 1)

    def peripheral_address(self, n: int) -> int:
        return self.w[self.regs[n][2]]

    def transfer_many(self, n: int, values) -> int:
        """Items from a peripheral to memory, one request each; returns how
        many moved (none while the channel is off, or once a non-circular
        one has counted down to 0)."""
        if n not in self.regs:
            return 0
        w, (i_ccr, i_cndtr, _, i_cmar) = self.w, self.regs[n]
        ccr = w[i_ccr]
        left = w[i_cndtr] & 0xFFFF
        if not ccr & 1:
            return 0
        total = self.reload.get(n, left)
        msize = 1 << ((ccr >> 10) & 3)
        base, minc, circular = w[i_cmar], ccr & (1 << 7), ccr & (1 << 5)
        mask = (1 << 8 * msize) - 1
        view, at = self.core.view(base)  # the memory the channel writes (one region: CMAR's)
        flags = moved = 0
        for value in values:
            if left == 0:
                break
            position = at + ((total - left) * msize if minc else 0)
            view[position:position + msize] = (value & mask).to_bytes(msize, "little")
            left, flags = self._counted(left - 1, total, circular, flags)
            moved += 1
        self._done(n, ccr, left, flags)
        return moved

    def take(self, n: int):
        """One item from memory for a peripheral (a channel with DIR set),
        or None while the channel is off or has counted down to 0."""
        if n not in self.regs:
            return None
        w, (i_ccr, i_cndtr, _, i_cmar) = self.w, self.regs[n]
        ccr = w[i_ccr]
        left = w[i_cndtr] & 0xFFFF
        if not ccr & 1 or left == 0:
            return None
        total = self.reload.get(n, left)
        msize = 1 << ((ccr >> 10) & 3)
        position = (total - left) if ccr & (1 << 7) else 0
        value = self.core.rd_bytes(w[i_cmar] + position * msize, msize)
        left, flags = self._counted(left - 1, total, ccr & (1 << 5), 0)
        self._done(n, ccr, left, flags)
        return value

    @staticmethod
    def _counted(left: int, total: int, circular: int, flags: int) -> tuple:
        """The counter after one item, and the flags that sets."""
        if left == total // 2:
            flags |= 0b0101  # GIF, HTIF
        if left == 0:
            flags |= 0b0011  # GIF, TCIF
            if circular:
                left = total
        return left, flags

    def _done(self, n: int, ccr: int, left: int, flags: int) -> None:
        self.w[self.regs[n][1]] = left
        if flags:
            self.w[self.i_isr] |= flags << 4 * (n - 1)
            if (flags & 2 and ccr & 2) or (flags & 4 and ccr & 4):  # TCIE, HTIE
                self.core.raise_irq(self.irqs[n])

    def transfer(self, n: int, value: int) -> bool:
        """One item from a peripheral to memory."""
        return self.transfer_many(n, (value,)) == 1
