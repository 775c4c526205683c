"""The Cortex-M3's memory protection unit (PMSAv7, ARMv7-M ARM B3.5) for
data accesses.

Registers (B3.5.5-B3.5.9): MPU_TYPE (0xE000ED90) reads DREGION = 8, the
Cortex-M3's data regions (Cortex-M3 TRM, DDI 0337, 11.1 "About the MPU":
eight regions); MPU_CTRL (ENABLE bit 0, HFNMIENA 1, PRIVDEFENA 2); MPU_RNR
selects the region MPU_RBAR and MPU_RASR show; MPU_RBAR with VALID (bit 4)
writes its REGION field (bits 3:0) to RNR first. A region is
2^(SIZE+1) bytes (SIZE, RASR bits 5:1, at least 4: 32 bytes), at a base
aligned to its size; its eight sub-regions (256 bytes and larger) are
left out by the bits of SRD (15:8); AP (26:24) gives the access
(table B3-15): 000 none, 001 privileged read-write, 010/011 read-write,
101 privileged read-only, 110/111 read-only. Where regions overlap the
highest-numbered one decides; where none matches, a privileged access
takes the default map if PRIVDEFENA is set and faults if not (B3.5.1).
The private peripheral bus (0xE0000000-0xE00FFFFF) always takes the
default map, and with HFNMIENA clear the MPU is off while HardFault or NMI
runs.

A violating load or store is a MemManage fault (DACCVIOL, MMARVALID, MMFAR
= the address; faults.py) and is not carried out: the hook stops the CPU
at it and its registers and memory are put back. Only while ENABLE is set,
and only over the enabled regions (with PRIVDEFENA clear: the whole map
but the PPB), is any access hooked. Instruction fetches (IACCVIOL, XN) are
not checked: the firmware runs from flash under the default map."""
from unicorn import UC_HOOK_MEM_READ, UC_HOOK_MEM_WRITE, UC_MEM_WRITE
from unicorn import arm_const as arm

from .exceptions import ENTRY_READ

MPU_TYPE, MPU_CTRL, MPU_RNR, MPU_RBAR, MPU_RASR = 0xE000ED90, 0xE000ED94, 0xE000ED98, 0xE000ED9C, 0xE000EDA0
DREGIONS = 8
CTRL_ENABLE, CTRL_HFNMIENA, CTRL_PRIVDEFENA = 1, 2, 4
RBAR_VALID = 1 << 4
PPB = (0xE0000000, 0xE0100000)
# AP (table B3-15) -> (privileged read, privileged write, unprivileged read, unprivileged write)
AP = {0: (0, 0, 0, 0), 1: (1, 1, 0, 0), 2: (1, 1, 1, 0), 3: (1, 1, 1, 1), 4: (0, 0, 0, 0),
      5: (1, 0, 0, 0), 6: (1, 0, 1, 0), 7: (1, 0, 1, 0)}
SNAPSHOT = ENTRY_READ + (arm.UC_ARM_REG_R4, arm.UC_ARM_REG_R5, arm.UC_ARM_REG_R6, arm.UC_ARM_REG_R7,
                         arm.UC_ARM_REG_R8, arm.UC_ARM_REG_R9, arm.UC_ARM_REG_R10, arm.UC_ARM_REG_R11)


class Mpu:
    """Mixed into Core (its uc, registers, memory, on_write, fix, defer)."""

    def _init_mpu(self) -> None:
        self.mpu_on = False
        self.mpu_regions = [(0, 0)] * DREGIONS  # (RBAR, RASR) as written
        self._mpu_hooks = []
        self.mpu_faults = 0
        if self.v7m:
            for address, handler in ((MPU_CTRL, self._mpu_ctrl), (MPU_RNR, self._mpu_rnr),
                                     (MPU_RBAR, self._mpu_rbar), (MPU_RASR, self._mpu_rasr)):
                self.on_write(address, handler)

    def _reset_mpu(self) -> None:
        self.mpu_regions = [(0, 0)] * DREGIONS
        self.mpu_on = False
        self._mpu_rehook()
        if self.v7m:
            self.wr32(MPU_TYPE, DREGIONS << 8)

    # ---- registers --------------------------------------------------------
    def _selected(self) -> int:
        return self.rd32(MPU_RNR) & (DREGIONS - 1)

    def _mpu_show(self, n: int) -> None:
        rbar, rasr = self.mpu_regions[n]
        self.fix(MPU_RBAR, (rbar & ~0x1F) | n)
        self.fix(MPU_RASR, rasr)

    def _mpu_ctrl(self, value, old, size):
        self.fix(MPU_CTRL, value & 7)
        self.defer(self._mpu_rehook)

    def _mpu_rnr(self, value, old, size):
        self.fix(MPU_RNR, value & 0xFF)
        self._mpu_show(value & (DREGIONS - 1))

    def _mpu_rbar(self, value, old, size):
        n = value & 0xF if value & RBAR_VALID else self._selected()
        n &= DREGIONS - 1
        if value & RBAR_VALID:
            self.fix(MPU_RNR, n)
        self.mpu_regions[n] = (value & ~0x1F, self.mpu_regions[n][1])
        self._mpu_show(n)
        self.defer(self._mpu_rehook)

    def _mpu_rasr(self, value, old, size):
        n = self._selected()
        self.mpu_regions[n] = (self.mpu_regions[n][0], value & 0x173FFF3F)
        self._mpu_show(n)
        self.defer(self._mpu_rehook)

    # ---- what it allows ---------------------------------------------------
    def _region_spans(self):
        """(number, base, end, RASR) of each enabled region, highest first."""
        for n in reversed(range(DREGIONS)):
            rbar, rasr = self.mpu_regions[n]
            if not rasr & 1 or (rasr >> 1) & 0x1F < 4:
                continue
            size = 2 << ((rasr >> 1) & 0x1F)
            base = rbar & ~(size - 1) & 0xFFFFFFE0
            yield n, base, base + size, rasr

    def mpu_allows(self, address: int, size: int, write: bool) -> bool:
        """Whether the MPU lets this data access through."""
        if not self.mpu_on:
            return True
        ctrl = self.rd32(MPU_CTRL)
        if PPB[0] <= address < PPB[1]:
            return True
        ipsr = self.reg(arm.UC_ARM_REG_IPSR) & 0x1FF
        if ipsr in (2, 3) and not ctrl & CTRL_HFNMIENA:
            return True
        privileged = ipsr != 0 or not self.reg(arm.UC_ARM_REG_CONTROL) & 1
        for at in {address, address + size - 1}:
            allowed = None
            for _, base, end, rasr in self._region_spans():
                if not base <= at < end:
                    continue
                sub = (end - base) // 8
                if end - base >= 256 and rasr >> 8 & (1 << ((at - base) // sub)):
                    continue  # this sub-region is left out of the region
                allowed = AP[rasr >> 24 & 7][(0 if privileged else 2) + bool(write)]
                break
            if allowed is None:
                allowed = privileged and ctrl & CTRL_PRIVDEFENA
            if not allowed:
                return False
        return True

    # ---- hooks ------------------------------------------------------------
    def _mpu_rehook(self) -> None:
        for h in self._mpu_hooks:
            self.uc.hook_del(h)
        self._mpu_hooks = []
        self.mpu_on = bool(self.v7m and self.rd32(MPU_CTRL) & CTRL_ENABLE)
        if not self.mpu_on:
            return
        if self.rd32(MPU_CTRL) & CTRL_PRIVDEFENA:
            spans = [(base, end - 1) for _, base, end, _ in self._region_spans()]
        else:
            spans = [(0, PPB[0] - 1), (PPB[1], 0xFFFFFFFF)]
        for begin, end in spans:
            self._mpu_hooks.append(self.uc.hook_add(UC_HOOK_MEM_READ | UC_HOOK_MEM_WRITE, self._mpu_hook,
                                                    begin=begin, end=end))

    def _mpu_hook(self, uc, access, address, size, value, data):
        write = access == UC_MEM_WRITE
        if self.mpu_allows(address, size, write):
            return
        self.stop_at_fault("MPU", "mem_data", address, restore=(address, size) if write else None)
        self.mpu_faults += 1

    def stop_at_fault(self, why: str, kind: str, address=None, restore=None) -> None:
        """From a memory hook: the CPU stops at this instruction, which is
        not carried out (its registers, and the bytes a store would
        overwrite, are put back), and the fault is taken."""
        snapshot = self.regs(SNAPSHOT)
        at_s = self.time_s + max(self.count.executed - 1, 0) * self.cpi / self.hz
        old = bytes(self.uc.mem_read(restore[0], restore[1])) if restore else None

        def take():
            self.set_regs(SNAPSHOT, snapshot)
            if restore:
                self.uc.mem_write(restore[0], old)
            self._fault(why, kind, address, at_s)
        self.defer(take)


def configure(core, regions: dict, ctrl: int) -> None:
    """Sets the MPU as a firmware's stores would (bench.py --mpu, tests):
    regions {number: (RBAR, RASR)}, then MPU_CTRL."""
    for n, (rbar, rasr) in regions.items():
        core.mpu_regions[n] = (rbar & ~0x1F, rasr)
    core.wr32(MPU_CTRL, ctrl)
    core._mpu_rehook()


def no_access(size_log2: int = 5) -> int:
    """RASR of an enabled region of 2^size_log2 bytes that nothing may access (AP 000)."""
    return ((size_log2 - 1) << 1) | 1
