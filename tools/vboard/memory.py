"""The virtual core's memory: host memory mapped into Unicorn, and the
write handlers of the peripheral registers.

Peripheral registers are RAM to the CPU, so reading them costs no Python;
writes call the peripheral's handler before the value lands. A handler that
makes the register read other than what was written (a write-1-to-clear
flag, a ready bit) or that stalls or resets the CPU stops it after the
store; the register then takes its value before the next instruction runs.
The CPU resumes after the store (a plain STR/STRH/STRB, which is what the
compiler makes of a register write), or, for any other store instruction
and for any store inside an IT block (whose state a jump over it would
break), runs it again, that second time past the handler, and the register
takes its value at the end of that slice."""
import ctypes
import struct

from unicorn import UC_HOOK_MEM_WRITE
from unicorn import arm_const as arm

from .system_space import SCS_BASE


class MemoryMap:
    """Memory and register writes of Core (core.py), which mixes this in:
    it has uc, handlers, ranges, regions, fixes, deferred, running and
    the fields _write_hook sets."""

    def map_host(self, base: int, size: int, buf=None):
        """Maps host memory at base (a new zeroed buffer unless given): the
        models read and write it directly, without going through Unicorn."""
        if buf is None:
            buf = (ctypes.c_ubyte * size)()
        self.uc.mem_map_ptr(base, size, 7, ctypes.addressof(buf))
        view = memoryview(buf).cast("B")
        self.regions.append((base, base + size, view))
        self._words[base] = view.cast("I")
        self._pages = {}
        return buf

    def words(self, address: int):
        """(address's host-mapped region as 32-bit words, its word's index)."""
        base, _ = self._region(address)
        return self._words[base], (address - base) // 4

    def map_system_control_space(self) -> None:
        """SysTick, the NVIC and the SCB, mapped after the board's memory:
        Unicorn 2.1 gives a host-memory block mapped after a smaller one the
        offset of the block before it in its RAM list, so with this 4 KB
        block first the flash and the SRAM shared offsets, and every store
        to the stack over the bytes of the hot code in flash threw its
        translation away (the F103's control tick ran 4 to 10 times slower).
        Mapped last, no two blocks share an offset (both boards' layouts,
        checked store by store)."""
        self.map_host(SCS_BASE, 0x1000)
        self.scs = self._words[SCS_BASE]

    def _region(self, address: int):
        """(base, view) of the host-mapped region holding address, by its
        1 KB page (the models touch a few pages very often), or None."""
        page = address >> 10
        hit = self._pages.get(page)
        if hit is None:
            hit = next(((base, view) for base, end, view in self.regions if base <= address < end), None)
            if hit is not None:
                self._pages[page] = hit
        return hit

    def view(self, address: int):
        """(address's host-mapped region as bytes, address's offset in it)."""
        hit = self._region(address)
        if hit is None:
            raise KeyError(f"{address:#010x} is not host-mapped")
        return hit[1], address - hit[0]

    def on_write(self, address: int, handler) -> None:
        """Stores into the register (word) at address go to
        handler(value, old, size) before they land."""
        self.handlers[address] = handler
        self._hooks_stale = True

    def on_write_range(self, begin: int, end: int, handler) -> None:
        """Stores into [begin, end) (memory, not registers) go to
        handler(address, value, size) before they land."""
        self.ranges.append((begin, end, handler))
        self._hooks_stale = True

    def _hook_writes(self) -> None:
        """One write hook per peripheral block (1 KB) from its first
        handled register to its last, and one per memory range: Unicorn
        runs a store that a write hook watches outside the IT block it is in
        (the block's state is lost), so stores to a peripheral without
        handlers (the PWM compares, set under IT) are not watched at all;
        and few hooks keep every other store cheap."""
        for h in self._write_hooks:
            self.uc.hook_del(h)
        blocks = {}
        for address in self.handlers:
            lo, hi = blocks.get(address >> 10, (address, address))
            blocks[address >> 10] = (min(lo, address), max(hi, address))
        spans = [(lo, hi + 3) for lo, hi in blocks.values()] + [(b, e - 1) for b, e, _ in self.ranges]
        self._write_hooks = [self.uc.hook_add(UC_HOOK_MEM_WRITE, self._write_hook, begin=b, end=e)
                             for b, e in spans]
        self._hooks_stale = False

    def _read(self, address: int, fmt: str) -> int:
        hit = self._region(address)
        if hit is not None:
            return struct.unpack_from(fmt, hit[1], address - hit[0])[0]
        return struct.unpack(fmt, self.uc.mem_read(address, struct.calcsize(fmt)))[0]  # an alias (address 0)

    def rd32(self, address: int) -> int:
        return self._read(address, "<I")

    def rd16(self, address: int) -> int:
        return self._read(address, "<H")

    def rd_bytes(self, address: int, size: int) -> int:
        return self._read(address, {1: "<B", 2: "<H", 4: "<I"}[size])

    def wr32(self, address: int, value: int) -> None:
        view, at = self.view(address)
        struct.pack_into("<I", view, at, value & 0xFFFFFFFF)

    def write(self, address: int, data: bytes) -> None:
        view, at = self.view(address)
        view[at:at + len(data)] = data

    def fix(self, address: int, value, size: int = 4) -> None:
        """The register (or memory) reads value (an int of size bytes, or
        bytes) from the instruction after the current store on."""
        data = value if isinstance(value, bytes) else (value & ((1 << 8 * size) - 1)).to_bytes(size, "little")
        self.fixes.append((address, data))
        self.uc.emu_stop()

    def defer(self, action) -> None:
        """From a handler: action() runs once the CPU has stopped after this
        store (before the next instruction)."""
        self.deferred.append(action)
        self.uc.emu_stop()

    def new_event(self) -> None:
        """From a handler: the peripheral acts sooner than this run would end
        (a byte shifting out): the CPU stops after this store."""
        if self.running:
            self.defer(lambda: None)

    def stop(self, stall_s: float = 0.0, reset: str = None) -> None:
        """From a handler: the CPU stops after this store, stalled for
        stall_s, or resets."""
        self.stall_s += stall_s
        if reset:
            self.reset_cause = reset
        self.uc.emu_stop()

    def _write_hook(self, uc, access, address, size, value, data):
        self.count.hooks += 1  # a pass that stores here is no idle pass (idle_skip.py)
        if self._passthrough == address:
            self._passthrough = None
            return
        word = address & ~3
        handler = self.handlers.get(word)
        if handler is None:
            for begin, end, memory_handler in self.ranges:
                if begin <= address < end:
                    memory_handler(address, value, size)
                    if self.fixes or self.stall_s or self.reset_cause or self.deferred:
                        self._stopping = address
                        self._stop_pc = self.reg(arm.UC_ARM_REG_PC)
            return
        shift = 8 * (address & 3)
        old = self.rd32(word)
        if size < 4:  # a byte or half-word store into a word register
            mask = ((1 << (8 * size)) - 1) << shift
            value = (old & ~mask) | ((value << shift) & mask)
        handler(value & 0xFFFFFFFF, old, size)
        if self.fixes or self.stall_s or self.reset_cause or self.deferred:
            self._stopping = address
            self._stop_pc = self.reg(arm.UC_ARM_REG_PC)
