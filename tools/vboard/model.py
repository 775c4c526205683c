"""What every peripheral model shares: its registers from the SVD, in the
core's memory, reset to the SVD's reset values."""
from .svd import Peripheral


class Model:
    def __init__(self, board, periph: Peripheral):
        self.board, self.core, self.p = board, board.core, periph
        # The registers as words of the core's memory: w[i[name]] reads or
        # writes one (a memoryview index, the cheapest access Python has;
        # models touch registers at every slice).
        self.w, first = self.core.words(periph.base)
        self.i = {name: first + offset // 4 for name, (offset, _, _) in periph.registers.items()}
        self._bits = {}  # (register, field) -> mask

    def addr(self, register: str) -> int:
        return self.p.address(register)

    def get(self, register: str) -> int:
        return self.w[self.i[register]]

    def put(self, register: str, value: int) -> None:
        self.w[self.i[register]] = value & 0xFFFFFFFF

    def bit(self, register: str, field: str) -> int:
        key = (register, field)
        mask = self._bits.get(key)
        if mask is None:
            mask = self._bits[key] = self.p.mask(register, field)
        return mask

    def watch(self, register: str, handler) -> None:
        self.core.on_write(self.p.address(register), handler)

    def reset(self) -> None:
        """The SVD's reset value in every register (RM0008 and RM0360 give
        the same, register by register)."""
        for address, value in self.p.reset_values():
            self.core.wr32(address, value)

    def step(self, now_s: float) -> None:
        """Called between the CPU's slices: catch up to now_s."""

    def next_event_s(self, now_s: float) -> float:
        """When this model next needs a slice boundary (inf: never)."""
        return float("inf")
