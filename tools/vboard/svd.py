"""Register layouts from ST's SVD files (cmsis-svd 0.4 bundles them): each
peripheral model takes its base address, register offsets, reset values and
bit fields from here, not from the firmware's headers."""
import functools

from cmsis_svd.parser import SVDParser


class Peripheral:
    def __init__(self, name: str, base: int, registers: dict):
        self.name, self.base = name, base
        self.registers = registers  # name -> (offset, reset value, {field: (offset, width)})

    def address(self, register: str) -> int:
        return self.base + self.registers[register][0]

    def mask(self, register: str, field: str) -> int:
        """The field's bits in its register."""
        offset, width = self.registers[register][2][field]
        return ((1 << width) - 1) << offset

    def shift(self, register: str, field: str) -> int:
        return self.registers[register][2][field][0]

    def reset_values(self):
        """(address, reset value) of every register."""
        return [(self.base + off, reset) for off, reset, _ in self.registers.values()]


@functools.lru_cache(maxsize=None)
def device(part: str) -> dict:
    """{peripheral name: Peripheral} of an STMicro part ("STM32F103xx", "STM32F030";
    "STM32G031", which cmsis-svd 0.4 lacks: g0_registers.py's table)."""
    if part == "STM32G031":
        from . import g0_registers
        return g0_registers.device()
    dev = SVDParser.for_packaged_svd("STMicro", part + ".svd").get_device()
    out = {}
    for p in dev.peripherals:
        regs = {r.name: (r.address_offset, r.reset_value or 0,
                         {f.name: (f.bit_offset, f.bit_width) for f in r.fields})
                for r in p.registers}
        out[p.name] = Peripheral(p.name, p.base_address, regs)
    return out


@functools.lru_cache(maxsize=None)
def interrupts(part: str) -> dict:
    """{interrupt name: number}."""
    if part == "STM32G031":
        from . import g0_registers
        return dict(g0_registers.INTERRUPTS)
    dev = SVDParser.for_packaged_svd("STMicro", part + ".svd").get_device()
    return {i.name: i.value for p in dev.peripherals for i in (p.interrupts or [])}
