"""The servo's own faults, injected from the control port (run.py's inject
and brownout), and what a fault handler does about the bridge, measured.

- bus: the next read the application makes of the USART receiver's DMA
  counter (CNDTR of its channel, RM0008 13.4.4, RM0360 10.4.4; the main
  loop reads it every pass to see what the wire brought, dma_rx.c) ends in
  an error response: a precise BusFault on the M3 (PRECISERR, BFARVALID,
  BFAR the address; ARMv7-M B3.2.15), a HardFault on the M0 (ARMv6-M
  B1.5.14). The load is not carried out; the stacked PC is its address.
- undef: the next instruction the application executes in thread mode is
  taken as undefined (UsageFault UNDEFINSTR on the M3, HardFault on the M0).
- stack: at the entry of the main loop's pass (servo_poll, called every
  pass), SP is lowered to just above the stack's bottom (the ELF's
  _estack - STACK_SIZE, hal/ports/stm32_common/linker/sections_stm32.ld), as if the
  function had a deep local array: on the M3 its frame (its pushes and
  locals, 64 bytes) reaches below the bottom, over the bottom word where
  the firmware keeps a guard; on the M0 its frame (read from its prologue) ends STACK_BELOW_FRAME
  bytes above the bottom, so that what it calls runs the stack out. At its return (its caller's address, its frame
  popped) SP is given back. With the M3's MPU guarding the bottom the push
  faults (MemManage, or HardFault if disabled); without, it overwrites.
- hang: the main loop stops at the start of its pass: thread mode spins
  there (interrupts still run) until a reset; the watchdog ends it.

After any fault, a write hook over TIM3's CR1 to CCR2 (RM0008 15.4, RM0360
13.4) finds the first store that leaves the bridge off (timers.py's
duty() None with the store applied) and notes the core time of that store's
instruction. The hook exists only from a fault to the next reset: a write
hook runs a store outside the IT block it is in (memory.py), and the
firmware sets its compares under IT while it runs normally."""
import struct

from unicorn import UC_HOOK_CODE, UC_HOOK_MEM_READ, UC_HOOK_MEM_WRITE
from unicorn import arm_const as arm

from .idle_skip import _elf, _symbol

KINDS = ("bus", "undef", "stack", "hang")
# SP at entry: this far above the bottom (8-byte aligned, AAPCS), so that
# the function's own pushes (48 bytes on the F103, 20 on the F030) come down
# into the stack's first bytes from above, as a stack that grows does: on
# the M3 across the bottom (where a firmware's MPU guard sits), on the M0
# inside its bottom 256 bytes, far enough above the static data below for
# an interrupt's frame on top of it (a stack that has just run out, not one
# that jumped past a whole guard).
STACK_SLACK_M3 = 40
STACK_BELOW_FRAME = 56  # the M0: room under servo_poll's frame for its callees' first pushes
CNDTR = 0x0C  # DMA channel 1's counter; channel n's at 0x0C + 20 (n - 1) (RM0008 13.4.4, RM0360 10.4.4)


def stack_facts(path):
    """(servo_poll's address, the stack's bottom, its frame's bytes) from the
    application's ELF, or None."""
    elf = _elf(path)
    poll = elf and _symbol(elf, "servo_poll")
    top, size = elf and _symbol(elf, "_estack"), elf and _symbol(elf, "STACK_SIZE")
    if not poll or not top or not size:
        return None
    return poll[0] & ~1, top[0] - size[0], _frame_bytes(elf, poll[0] & ~1)


def _frame_bytes(elf, address: int) -> int:
    """What a Thumb function's prologue takes off SP, read up to its first
    branch, call or return (the compiler mixes the body's first
    instructions into it): `push` (a register each, LR too), `sub sp,
    #imm`, and a large frame's `ldr rN, =-size; add sp, rN` (ARMv6-M
    A6.7.50, A6.7.67, A6.7.30, A6.7.3; the M3's `stmdb sp!`, A7.7.160)."""
    data, sections = elf
    for sh in sections:  # (name, type, flags, addr, offset, size, ...)
        if sh[3] <= address < sh[3] + sh[5] and sh[1] == 1:  # SHT_PROGBITS
            base, offset, size = sh[3], sh[4], sh[5]
            break
    else:
        return 0

    def half(at):
        return struct.unpack_from("<H", data, offset + at - base)[0] if base <= at < base + size - 1 else None

    total, loaded, at = 0, {}, address
    for _ in range(16):
        h = half(at)
        if h is None:
            break
        if h & 0xFE00 == 0xB400:  # push {registers[, lr]}
            total += 4 * (bin(h & 0xFF).count("1") + (h >> 8 & 1))
        elif h == 0xE92D:  # stmdb sp!, {registers}
            total += 4 * bin(half(at + 2) or 0).count("1")
            at += 2
        elif h & 0xFF80 == 0xB080:  # sub sp, #imm7 * 4
            total += 4 * (h & 0x7F)
        elif h & 0xF800 == 0x4800:  # ldr rN, [pc, #imm8 * 4]: a large frame's size
            literal = ((at + 4) & ~3) + 4 * (h & 0xFF)
            if base <= literal < base + size - 3:
                loaded[h >> 8 & 7] = struct.unpack_from("<i", data, offset + literal - base)[0]
        elif h & 0xFF87 == 0x4485 and (h >> 3 & 0xF) in loaded:  # add sp, rN
            total -= loaded[h >> 3 & 0xF]
        elif h & 0xFF00 in (0x4700, 0xBD00, 0xBC00) or 0xD000 <= h < 0xE800 or h & 0xF800 == 0xF000:
            break  # bx/blx, pop, a branch, bl: the prologue is over
        elif h >= 0xE800:
            at += 2  # another 32-bit instruction: its second half
        at += 2
    return total


class Injector:
    def __init__(self, board, elf_path):
        self.board, self.core = board, board.core
        self.counts = dict.fromkeys(KINDS, 0)
        self.brownouts = 0
        self.facts = stack_facts(elf_path)
        dma, channel = board.dma, board.part.usart_rx_dma
        self.bus_register = dma.p.base + CNDTR + 20 * (channel - 1)
        self.armed = None            # the kind waiting to happen
        self.hooks = []
        self.lowered = None          # (return address, SP lowered to, by how much) while the frame runs
        self.bridge_hook = None
        self.bridge_off_at_s = None
        self.hung_at_s = None        # core time the main loop stopped (hang)
        self.overflow_at_s = None    # core time the stack's frame was lowered (stack)
        self.skip_idle = self.core.skip_idle
        self.core.on_fault = self._faulted

    def inject(self, kind: str) -> str:
        if kind not in KINDS:
            return f"error: inject takes ID and one of {', '.join(KINDS)}"
        if kind in ("stack", "hang") and self.facts is None:
            return "error: the application's ELF names no servo_poll, _estack and STACK_SIZE"
        app = (self.board.h["BOARD_SLOT_BASE"], self.board.h["BOARD_CONFIG_PAGE0"] - 1)
        self._unhook()
        uc = self.core.uc
        self.armed = kind
        self.counts[kind] += 1
        self.core.skip_idle = False  # a hook's stop is no idle pass
        if kind == "bus":
            self.hooks.append((uc.hook_add(UC_HOOK_MEM_READ, self._bus, begin=self.bus_register,
                                           end=self.bus_register + 3), None))
        elif kind == "undef":
            self._hook_code(self._undef, *app)
        else:
            self._hook_code(self._pass_start, self.facts[0], self.facts[0])
        return "ok"

    def _hook_code(self, callback, begin: int, end: int) -> None:
        """A code hook over [begin, end]: Unicorn puts code hooks into the
        code it translates, so what it translated there before is dropped."""
        uc = self.core.uc
        self.hooks.append((uc.hook_add(UC_HOOK_CODE, callback, begin=begin, end=end), (begin, end + 1)))
        uc.ctl_remove_cache(begin, end + 1)

    def _unhook(self) -> None:
        """Between runs only (never from a hook)."""
        for h, span in self.hooks:
            self.core.uc.hook_del(h)
            if span is not None:
                self.core.uc.ctl_remove_cache(*span)  # and the hook's calls with it
        self.hooks = []

    def reset(self) -> None:
        """The chip reset: nothing injected survives it."""
        self._unhook()
        self.armed, self.lowered = None, None
        if self.bridge_hook is not None:
            self.core.uc.hook_del(self.bridge_hook)
            self.bridge_hook = None
        self.core.skip_idle = self.skip_idle

    def _thread_mode(self) -> bool:
        return not self.core.reg(arm.UC_ARM_REG_IPSR) & 0x1FF

    # ---- the hooks (inside the emulator: they stop it, Python acts after) --
    def _bus(self, uc, access, address, size, value, data):
        if self.armed == "bus":
            self.armed = None
            self.core.stop_at_fault("injected bus error", "bus_data", address)
            self.core.defer(self._unhook)

    def _undef(self, uc, address, size, data):
        if self.armed == "undef" and self._thread_mode():
            self.armed = None
            self.core.stop_at_fault("injected undefined instruction", "undef")
            self.core.defer(self._unhook)

    def _pass_start(self, uc, address, size, data):
        core = self.core
        if self.lowered is not None and address == self.lowered[0]:
            if core.reg(arm.UC_ARM_REG_SP) == self.lowered[1]:  # returned, its frame popped
                by, self.lowered = self.lowered[2], None

                def give_back():
                    core.set_reg(arm.UC_ARM_REG_SP, core.reg(arm.UC_ARM_REG_SP) + by)
                    self._unhook()
                    core.skip_idle = self.skip_idle
                core.defer(give_back)
            return
        if not self._thread_mode() or address != self.facts[0]:
            return
        if self.armed == "hang" or core.spin_at == address:  # again after each handler returns here
            if self.armed == "hang":
                self.hung_at_s = core.time_s + max(core.count.executed - 1, 0) * core.cpi / core.hz
            self.armed = None
            core.spin_at = address
            core.defer(lambda: None)  # stopped here, not at a WFI
        elif self.armed == "stack":
            self.armed = None
            sp = core.reg(arm.UC_ARM_REG_SP)
            bottom, frame = self.facts[1], self.facts[2]
            low = bottom + (STACK_SLACK_M3 if core.v7m else (frame + STACK_BELOW_FRAME + 7) & ~7)
            back = core.reg(arm.UC_ARM_REG_LR) & ~1
            self.lowered = (back, low, sp - low)

            def lower():
                self.overflow_at_s = core.time_s  # the frame's pushes come next
                core.set_reg(arm.UC_ARM_REG_SP, low)
                self._hook_code(self._pass_start, back, back)
            core.defer(lower)

    # ---- the bridge after a fault -------------------------------------------
    def _faulted(self) -> None:
        """From Core._fault, between runs: watch the bridge from now."""
        self.bridge_off_at_s = None
        if self.bridge_hook is None:
            tim = self.board.tim
            self.bridge_hook = self.core.uc.hook_add(UC_HOOK_MEM_WRITE, self._bridge_store,
                                                     begin=tim.addr("CR1"), end=tim.addr("CCR2") + 3)

    def _bridge_store(self, uc, access, address, size, value, data):
        if self.bridge_off_at_s is not None:
            return
        tim = self.board.tim
        words = {name: tim.get(name) for name in ("CR1", "CCER", "CCR1", "CCR2", "ARR")}
        for name in words:
            at = tim.addr(name)
            if at <= address < at + 4:
                shift = 8 * (address - at)
                mask = ((1 << (8 * size)) - 1) << shift
                words[name] = (words[name] & ~mask) | ((value << shift) & mask)
        if tim.duty_of(**words) is None:
            core = self.core
            self.bridge_off_at_s = core.time_s + max(core.count.executed - 1, 0) * core.cpi / core.hz

    def state(self) -> dict:
        c = self.core
        ms = lambda s: "none" if s is None else round(s * 1000, 6)  # noqa: E731
        return {"fault_at_ms": ms(c.fault_at_s), "bridge_off_at_ms": ms(self.bridge_off_at_s),
                "hung_at_ms": ms(self.hung_at_s),
                "exceptions_taken": ",".join(f"{e}:{n}" for e, n in sorted(c.taken.items())) or "none",
                "injected": ",".join(f"{k}:{n}" for k, n in self.counts.items()),
                "inject_armed": self.armed or "none", "brownouts": self.brownouts, "mpu_faults": c.mpu_faults,
                "reset_flags": f"{self.board.rcc.get('CSR'):#010x}"}
