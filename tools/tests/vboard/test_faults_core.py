"""The virtual core's faults against the architecture, with a hand-assembled
Thumb program (offsets from PROGRAM, arm-none-eabi-as -mcpu=cortex-m3):

    0x00 bus:   ldr r1, [r0]; b .          (r0: an address with nothing there)
    0x10 undef: udf #0; b .
    0x20 mpu:   region 0 = 0x20000400, 32 bytes, AP 000 (no access), enabled
                through MPU_RBAR (VALID) and MPU_RASR; MPU_CTRL = ENABLE |
                PRIVDEFENA; then 0x34: ldr r3, [0x20000404]; b .
    0x60 w:     str r3, [r2]; b .

On the Cortex-M3 (ARMv7-M ARM B1.5.14, B3.2.15-B3.2.19) a fault is its own
exception when SHCSR enables it, else HardFault with HFSR.FORCED; on the
Cortex-M0 (ARMv6-M) every fault is a HardFault. The faulting instruction
is not carried out, and its address is the stacked PC."""
import struct

import pytest
from unicorn import arm_const as arm

from vboard.core import Core
from vboard.faults import (BFARVALID, DACCVIOL, HFSR_FORCED, MMARVALID, MSTKERR, PRECISERR, SCB_BFAR, SCB_CFSR,
                           SCB_HFSR, SCB_MMFAR, SCB_SHCSR, UNDEFINSTR)
from vboard.mpu import MPU_CTRL, MPU_RASR, MPU_RBAR, MPU_TYPE
from vboard.system_space import FIRST_IRQ, NVIC_IPR, SCB_VTOR

FLASH, RAM = 0x08000000, 0x20000000
PROGRAM = FLASH + 0x100
HZ = 1_000_000
NOTHING = 0x60000000  # no memory there: the bus answers with an error
CODE = bytes.fromhex(
    "0168fee700000000000000000000000000defee70000000000000000000000001048114901604ff009014160052140f8081c"
    "0e4a1368fee7000000000000000000000000000000000000000000000000000000000000000000000000000000001360fee7"
    "9ced00e01004002004040020")
SPIN = bytes.fromhex("fee7")  # b .: every handler


def make(cpu):
    c = Core(cpu, HZ, 1.0, cpu != arm.UC_CPU_ARM_CORTEX_M0, 1)
    c.map_host(FLASH, 0x1000)
    if not c.v7m:
        c.map_host(0, 0x1000)  # the M0 has no VTOR: its vectors at 0 (the boot alias)
    c.map_host(RAM, 0x1000)
    c.map_system_control_space()
    vectors = [FLASH + 0x801 + 0x10 * n for n in range(32)]  # handler n at 0x800 + 16 n: b .
    vectors[0], vectors[1] = RAM + 0x800, PROGRAM + 1
    c.write(FLASH, struct.pack("<32I", *vectors))
    if not c.v7m:
        c.write(0, struct.pack("<32I", *vectors))
    for n in range(32):
        c.write(FLASH + 0x800 + 0x10 * n, SPIN)
    c.write(PROGRAM, CODE)
    c.reset(FLASH if c.v7m else 0)
    if c.v7m:
        c.wr32(SCB_VTOR, FLASH)
    return c


@pytest.fixture
def m3():
    return make(arm.UC_CPU_ARM_CORTEX_M3)


@pytest.fixture
def m0():
    return make(arm.UC_CPU_ARM_CORTEX_M0)


def reg(core, name):
    return core.reg(getattr(arm, "UC_ARM_REG_" + name))


def frame(core):
    return struct.unpack("<8I", bytes(core.uc.mem_read(reg(core, "SP"), 32)))


def run_for(core, seconds):
    """Runs of the core to that much more time (a store to a register
    with a handler ends a run)."""
    end = core.now_s() + seconds
    while core.now_s() < end - 1e-9:
        core.run(end - core.now_s())


def start_at(core, offset, **regs):
    core.set_reg(arm.UC_ARM_REG_PC, PROGRAM + offset + 1)
    for name, value in regs.items():
        core.set_reg(getattr(arm, "UC_ARM_REG_" + name.upper()), value)


def test_a_bus_error_escalates_to_hardfault_unless_busfault_is_enabled(m3):
    start_at(m3, 0x00, r0=NOTHING, r1=0x1234)
    m3.run(10e-6)
    assert reg(m3, "IPSR") == 3 and m3.taken == {3: 1}
    assert m3.rd32(SCB_HFSR) == HFSR_FORCED
    assert m3.rd32(SCB_CFSR) == PRECISERR | BFARVALID and m3.rd32(SCB_BFAR) == NOTHING
    stacked = frame(m3)
    assert stacked[6] == PROGRAM and stacked[1] == 0x1234  # not carried out: r1 as it was
    assert m3.fault_at_s == pytest.approx(0.0)


def test_an_enabled_busfault_is_taken_as_itself_and_its_flags_clear_by_writing_one(m3):
    m3.wr32(SCB_SHCSR, 1 << 17)
    start_at(m3, 0x00, r0=NOTHING)
    m3.run(10e-6)
    assert reg(m3, "IPSR") == 5 and m3.rd32(SCB_HFSR) == 0
    assert m3.rd32(SCB_CFSR) == PRECISERR | BFARVALID and frame(m3)[6] == PROGRAM
    assert m3.rd32(SCB_SHCSR) & 2  # BUSFAULTACT
    # A store of PRECISERR alone to CFSR (the handler's) clears that bit only.
    m3.write(FLASH + 0x900, bytes.fromhex("0160" "fee7"))  # str r1, [r0]; b .
    m3.set_regs((arm.UC_ARM_REG_R0, arm.UC_ARM_REG_R1, arm.UC_ARM_REG_PC), (SCB_CFSR, PRECISERR, FLASH + 0x901))
    m3.run(10e-6)
    assert m3.rd32(SCB_CFSR) == BFARVALID


def test_a_busfault_below_the_execution_priority_escalates(m3):
    m3.wr32(SCB_SHCSR, 1 << 17)
    m3.set_reg(arm.UC_ARM_REG_PRIMASK, 1)  # execution priority 0: BusFault at 0 cannot preempt it
    start_at(m3, 0x00, r0=NOTHING)
    m3.run(10e-6)
    assert reg(m3, "IPSR") == 3 and m3.rd32(SCB_HFSR) == HFSR_FORCED


def test_an_undefined_instruction_is_a_usagefault(m3):
    m3.wr32(SCB_SHCSR, 1 << 18)
    start_at(m3, 0x10)
    m3.run(10e-6)
    assert reg(m3, "IPSR") == 6 and m3.rd32(SCB_CFSR) == UNDEFINSTR and frame(m3)[6] == PROGRAM + 0x10


@pytest.mark.parametrize("offset, regs", [(0x00, {"r0": NOTHING}), (0x10, {})])
def test_the_m0_has_only_hardfault(m0, offset, regs):
    start_at(m0, offset, **regs)
    m0.run(10e-6)
    assert reg(m0, "IPSR") == 3 and frame(m0)[6] == PROGRAM + offset
    assert m0.rd32(SCB_CFSR) == 0 and m0.rd32(SCB_HFSR) == 0 and m0.rd32(MPU_TYPE) == 0  # none of these


def test_a_fault_in_hardfault_locks_the_core_up(m3):
    start_at(m3, 0x00, r0=NOTHING)
    m3.run(10e-6)
    m3.set_regs((arm.UC_ARM_REG_R0, arm.UC_ARM_REG_PC), (NOTHING, PROGRAM + 1))  # the handler does it again
    m3.run(10e-6)
    assert m3.locked_up


def test_the_mpu_faults_a_load_from_a_no_access_region(m3):
    assert m3.rd32(MPU_TYPE) == 8 << 8
    m3.wr32(SCB_SHCSR, 1 << 16)
    start_at(m3, 0x20, r3=0x77)
    run_for(m3, 50e-6)
    assert m3.rd32(MPU_CTRL) == 5 and m3.rd32(MPU_RBAR) == RAM + 0x400 and m3.rd32(MPU_RASR) == 9
    assert reg(m3, "IPSR") == 4 and m3.taken == {4: 1}
    assert m3.rd32(SCB_CFSR) == DACCVIOL | MMARVALID and m3.rd32(SCB_MMFAR) == RAM + 0x404
    stacked = frame(m3)
    assert stacked[6] == PROGRAM + 0x34 and stacked[3] == 0x77  # r3 not loaded


def test_the_mpu_faults_a_store_and_keeps_the_memory(m3):
    start_at(m3, 0x20)
    run_for(m3, 50e-6)  # the region set, then the load: escalated, MemManage is off
    assert reg(m3, "IPSR") == 3 and m3.rd32(SCB_HFSR) == HFSR_FORCED
    m3.wr32(RAM + 0x408, 0xCAFE)
    m3.active, m3.locked_up = [], False
    m3.set_regs((arm.UC_ARM_REG_R2, arm.UC_ARM_REG_R3, arm.UC_ARM_REG_IPSR, arm.UC_ARM_REG_PC),
                (RAM + 0x408, 0xDEAD, 0, PROGRAM + 0x61))
    m3.run(10e-6)
    assert m3.rd32(RAM + 0x408) == 0xCAFE and frame(m3)[6] == PROGRAM + 0x60
    assert m3.rd32(SCB_MMFAR) == RAM + 0x408


def test_stacking_into_a_no_access_region_is_mstkerr_without_mmfar(m3):
    m3.wr32(SCB_SHCSR, 1 << 16)
    start_at(m3, 0x20)
    run_for(m3, 8e-6)  # the region set, not yet loaded from
    assert m3.mpu_on and reg(m3, "IPSR") == 0
    m3.wr32(SCB_CFSR, 0)
    m3.wr32(NVIC_IPR, 0x80)
    m3.enabled.add(0)
    m3.set_regs((arm.UC_ARM_REG_SP, arm.UC_ARM_REG_PC), (RAM + 0x430, PROGRAM + 0x61))
    m3.wr32(SCB_MMFAR, 0)
    m3.raise_irq(0)
    m3.run(10e-6)
    assert reg(m3, "IPSR") == 4 and FIRST_IRQ in m3.pending  # the fault first, the interrupt waits
    assert m3.rd32(SCB_CFSR) == MSTKERR and m3.rd32(SCB_MMFAR) == 0
    assert reg(m3, "SP") == RAM + 0x410
