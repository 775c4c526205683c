"""What every peripheral model shares: its registers from the SVD, in the
core's memory, reset to the SVD's reset values."""
from .svd import Peripheral


class Model:
    def __init__(self, board, periph: Peripheral):
        self.board, self.core, self.p = board, board.core, periph

    def addr(self, register: str) -> int:
        return self.p.address(register)

    def get(self, register: str) -> int:
        return self.core.rd32(self.p.address(register))

    def put(self, register: str, value: int) -> None:
        self.core.wr32(self.p.address(register), value)

    def bit(self, register: str, field: str) -> int:
        return self.p.mask(register, field)

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
