"""The virtual boards' core (tools/vboard/core.py) against the architecture
(ARMv7-M ARM B1.5): exception entry and return with the stacked frame,
preemption by priority (a higher one preempts, an equal one waits), and a
fault that cannot be stacked locking the core up. A hand-assembled Thumb
program:

    thread  0x100: adds r0,#1; b 0x100
    IRQ 0   0x200: adds r1,#1; cmp r1,#200; bne 0x200; bx lr
    SysTick 0x300: adds r4,#1; bx lr  (r4 is not stacked: the count stays)
    sleeper 0x400: cpsid i; wfi; cpsie i; adds r5,#1; b 0x400
    masked  0x500: cpsid i; adds r6,#1; cpsie i; 0x506: adds r0,#1; b 0x506
"""
import struct

import pytest
from unicorn import arm_const as arm

from vboard.core import Core
from vboard.system_space import FIRST_IRQ, NVIC_IPR, SCB_SHPR3, SCB_VTOR, SYSTICK

FLASH, RAM = 0x08000000, 0x20000000
HZ = 1_000_000  # one instruction a microsecond (cpi 1): run(n us) runs n instructions


@pytest.fixture
def core():
    c = Core(arm.UC_CPU_ARM_CORTEX_M3, HZ, 1.0, True, 1)
    c.map_host(FLASH, 0x1000)
    c.map_host(RAM, 0x1000)
    c.map_system_control_space()
    vectors = [0] * 32
    vectors[0], vectors[1] = RAM + 0x800, FLASH + 0x101
    vectors[SYSTICK], vectors[FIRST_IRQ] = FLASH + 0x301, FLASH + 0x201
    c.write(FLASH, struct.pack("<32I", *vectors))
    c.write(FLASH + 0x100, bytes.fromhex("0130" "fde7"))
    c.write(FLASH + 0x200, bytes.fromhex("0131" "c829" "fcd1" "7047"))
    c.write(FLASH + 0x300, bytes.fromhex("0134" "7047"))
    c.write(FLASH + 0x400, bytes.fromhex("72b6" "30bf" "62b6" "0135" "f9e7"))
    c.write(FLASH + 0x500, bytes.fromhex("72b6" "0136" "62b6" "0130" "fde7"))
    c.reset(FLASH)
    c.wr32(SCB_VTOR, FLASH)
    c.wr32(NVIC_IPR, 0x80)           # IRQ 0 at 0x80
    c.wr32(SCB_SHPR3, 0x00 << 24)    # SysTick at 0x00: higher
    c.enabled.add(0)
    return c


def reg(core, name):
    return core.uc.reg_read(getattr(arm, "UC_ARM_REG_" + name))


def test_an_interrupt_is_entered_and_left_with_the_frame(core):
    core.run(10e-6)
    r0 = reg(core, "R0")
    core.raise_irq(0)
    core.run(10e-6)
    assert reg(core, "IPSR") == FIRST_IRQ and reg(core, "LR") == 0xFFFFFFF9
    sp = reg(core, "SP")
    frame = struct.unpack("<8I", core.uc.mem_read(sp, 32))
    assert frame[0] == r0 and frame[6] & ~1 in (FLASH + 0x100, FLASH + 0x102)
    assert frame[7] & (1 << 24)  # the Thumb bit
    core.run(700e-6)  # 200 rounds of the handler, then the thread again
    assert reg(core, "IPSR") == 0
    assert reg(core, "SP") == RAM + 0x800
    assert reg(core, "R1") == 0  # stacked and restored
    assert reg(core, "R0") > r0


def test_a_higher_priority_preempts_an_equal_one_waits(core):
    core.raise_irq(0)
    core.run(10e-6)
    assert reg(core, "IPSR") == FIRST_IRQ
    core.pending.add(SYSTICK)
    core.run(10e-6)  # SysTick preempts, returns to the IRQ handler
    assert reg(core, "R4") == 1
    assert reg(core, "IPSR") == FIRST_IRQ
    core.raise_irq(0)  # the same priority: waits for the running handler
    core.run(10e-6)
    assert reg(core, "IPSR") == FIRST_IRQ and FIRST_IRQ in core.pending
    core.run(2000e-6)  # both rounds of IRQ 0, then the thread
    assert not core.pending and reg(core, "IPSR") == 0


def test_primask_holds_every_interrupt(core):
    core.uc.reg_write(arm.UC_ARM_REG_PRIMASK, 1)
    core.raise_irq(0)
    core.run(20e-6)
    assert reg(core, "IPSR") == 0 and FIRST_IRQ in core.pending


def test_an_interrupt_primask_held_is_taken_right_after_cpsie(core):
    """Awake, not after a WFI: the run ends at the CPSIE I, and the next
    takes the interrupt before the instruction after it (B1.4.3), however
    long the slice (a busy main loop's interrupt was taken a slice late)."""
    core.set_reg(arm.UC_ARM_REG_PC, FLASH + 0x501)
    core.run(1e-6)  # cpsid i
    assert reg(core, "PRIMASK") == 1
    core.raise_irq(0)
    start = core.now_s()
    core.run(1e-3)  # adds r6, cpsie i: no further
    assert core.now_s() - start == pytest.approx(2e-6)
    assert reg(core, "PRIMASK") == 0 and reg(core, "R0") == 0 and reg(core, "R6") == 1
    core.run(10e-6)
    assert reg(core, "IPSR") == FIRST_IRQ
    frame = struct.unpack("<8I", core.uc.mem_read(reg(core, "SP"), 32))
    assert frame[0] == 0 and frame[6] == FLASH + 0x506  # before the thread's next instruction


def test_a_fault_that_cannot_be_stacked_locks_the_core_up(core):
    core.uc.reg_write(arm.UC_ARM_REG_SP, 0x50000000)
    core.uc.reg_write(arm.UC_ARM_REG_PC, 0x00000001 | 0x30000000)  # nothing there
    core.run(10e-6)
    assert core.locked_up
    r0 = reg(core, "R0")
    core.run(100e-6)
    assert reg(core, "R0") == r0  # runs nothing until a reset
    core.reset(FLASH)
    assert not core.locked_up


def sleeper(core):
    core.set_reg(arm.UC_ARM_REG_PC, FLASH + 0x401)


def test_wfi_sleeps_until_an_enabled_interrupt_then_takes_it_after_cpsie(core):
    sleeper(core)
    core.run(10e-6)
    assert core.asleep and reg(core, "PRIMASK") == 1
    r5, executed = reg(core, "R5"), core.count.executed
    assert executed == 2  # cpsid, wfi: the rest of the slice slept
    core.run(1e-3)
    assert core.asleep and reg(core, "R5") == r5 and core.slept_s > 1e-3
    core.raise_irq(1)  # not enabled: no wake
    core.run(10e-6)
    assert core.asleep
    core.raise_irq(0)  # enabled, PRIMASK set: it wakes, CPSIE, the handler runs
    core.run(1e-3)
    assert FIRST_IRQ not in core.pending and reg(core, "IPSR") == 0  # taken, and returned
    assert reg(core, "PRIMASK") == 1 and reg(core, "R5") == r5 + 1 and core.asleep  # one pass, asleep again


def test_the_instructions_a_run_executes_are_what_it_costs(core):
    core.run(50e-6)  # the thread loop: 50 instructions at one a microsecond
    assert core.count.executed == 50
    assert core.now_s() == pytest.approx(50e-6)
    sleeper(core)
    before = core.now_s()
    core.run(100e-6)  # two instructions, then 98 us asleep
    assert core.count.executed == 2
    assert core.now_s() - before == pytest.approx(100e-6) and core.slept_s == pytest.approx(98e-6)
