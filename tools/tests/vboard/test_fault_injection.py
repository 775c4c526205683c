"""The servo's own faults injected into the shipped images on both virtual
boards (vboard/inject.py, the control port's inject and brownout), taken
as the architecture says: the exception number, on the Cortex-M3 the
CFSR/HFSR bits and the fault address (ARMv7-M ARM B3.2.15-B3.2.19), the
stacked PC the faulting instruction. Today's handlers spin, so the bridge
stays as it was until the watchdog resets the chip: these tests check the
mechanics, not what the firmware will do about it. Runs in this process
(the runner's control-port commands, as a client's); every time is the
boards' simulated time."""
import struct

import pytest
from unicorn import arm_const as arm

from vboard import bench, mpu
from vboard.faults import (BFARVALID, DACCVIOL, HFSR_FORCED, MMARVALID, MSTKERR, PRECISERR, SCB_BFAR, SCB_CFSR,
                           SCB_HFSR, SCB_MMFAR, SCB_SHCSR, UNDEFINSTR)

from .test_virtual_boards import BOARDS, start

RMVF = 1 << 24
PORRSTF, PINRSTF, IWDGRSTF = 1 << 27, 1 << 26, 1 << 29  # RCC_CSR (RM0008 7.3.10, RM0360 6.4.10)
WATCHDOG_S = (1250 + 1) * 4 / 40_000  # the firmware's IWDG: RLR 1250, 40 kHz / 4 (board_common.c; timers.py)


@pytest.fixture(params=BOARDS)
def runner(request, tmp_path):
    r = bench.runner_for(request.param, [1], str(tmp_path / "state"))
    try:
        yield r
    finally:
        r.bus.close()
        r.control.close()
        r.clock.close()


def run(runner, seconds, until=None):
    """Steps the boards on by seconds, or until until() holds."""
    end = runner.now_s + seconds
    while runner.now_s < end:
        runner.step()
        if until is not None and until():
            return True
    return False


def state(runner) -> dict:
    return dict(pair.split("=", 1) for pair in runner.command("state 1").split())


def taken(runner) -> dict:
    return {int(e): int(n) for e, n in (p.split(":") for p in state(runner)["exceptions_taken"].split(","))}


def stacked_pc(core) -> int:
    return struct.unpack_from("<8I", bytes(core.uc.mem_read(core.reg(arm.UC_ARM_REG_SP), 32)))[6]


def faulted(runner):
    before = runner.now_s
    core = runner.boards[0].core
    assert run(runner, 0.05, lambda: core.fault_at_s is not None)
    assert before <= core.fault_at_s <= runner.now_s
    assert float(state(runner)["fault_at_ms"]) == pytest.approx(core.fault_at_s * 1000, abs=1e-3)
    return core


def test_a_bus_error_on_a_register_the_main_loop_reads(runner):
    board = runner.boards[0]
    assert runner.command("inject 1 bus") == "ok"
    core = faulted(runner)
    assert core.reg(arm.UC_ARM_REG_IPSR) == 3 and taken(runner).get(3) == 1
    assert stacked_pc(core) == core.fault_pc
    if core.v7m:  # the firmware leaves BusFault disabled: escalated
        assert core.rd32(SCB_HFSR) == HFSR_FORCED
        assert core.rd32(SCB_CFSR) == PRECISERR | BFARVALID
        assert core.rd32(SCB_BFAR) == board.injector.bus_register
    s = state(runner)
    assert s["injected"].startswith("bus:1") and s["inject_armed"] == "none"
    assert s["bridge_off_at_ms"] == "none"  # the handler spins: no store to the bridge


def test_a_busfault_enabled_is_taken_as_its_own(runner):
    core = runner.boards[0].core
    if not core.v7m:
        pytest.skip("ARMv6-M has HardFault only")
    core.wr32(SCB_SHCSR, 1 << 17)  # BUSFAULTENA, as a firmware that enables it
    runner.command("inject 1 bus")
    faulted(runner)
    assert core.reg(arm.UC_ARM_REG_IPSR) == 5 and taken(runner).get(5) == 1 and 3 not in taken(runner)
    assert core.rd32(SCB_HFSR) == 0 and core.rd32(SCB_CFSR) == PRECISERR | BFARVALID
    assert stacked_pc(core) == core.fault_pc


def test_an_undefined_instruction_in_thread_mode(runner):
    board = runner.boards[0]
    core = board.core
    if core.v7m:
        core.wr32(SCB_SHCSR, 1 << 18)  # USGFAULTENA
    assert runner.command("inject 1 undef") == "ok"
    faulted(runner)
    expected = 6 if core.v7m else 3
    assert core.reg(arm.UC_ARM_REG_IPSR) == expected and taken(runner).get(expected) == 1
    assert stacked_pc(core) == core.fault_pc
    assert board.h["BOARD_SLOT_BASE"] <= core.fault_pc < board.h["BOARD_CONFIG_PAGE0"]
    if core.v7m:
        assert core.rd32(SCB_CFSR) == UNDEFINSTR


def test_the_watchdog_ends_a_fault_whose_handler_spins(runner):
    board = runner.boards[0]
    runner.command("inject 1 undef")
    faulted(runner)
    bites_s = board.iwdg.bites_s
    assert bites_s - board.iwdg.kicked_s == pytest.approx(WATCHDOG_S)
    assert run(runner, 0.2, lambda: board.resets["watchdog"] == 1)
    assert bites_s <= runner.now_s < bites_s + 1e-3
    assert board.rcc.get("CSR") & (IWDGRSTF | PINRSTF) == IWDGRSTF | PINRSTF


def test_a_store_after_the_fault_that_leaves_the_bridge_off_is_timed(runner):
    """As the firmware's handlers will: CCER cleared, here by a store put
    in the handler's place (str r1, [r0]; b .)."""
    board = runner.boards[0]
    core = board.core
    runner.command("inject 1 undef")
    faulted(runner)
    snippet = board.injector.facts[1] + 0x100  # unused stack, far below the frame
    core.write(snippet, bytes.fromhex("0160" "fee7"))
    core.set_regs((arm.UC_ARM_REG_R0, arm.UC_ARM_REG_R1, arm.UC_ARM_REG_PC),
                  (board.tim.addr("CCER"), 0, snippet | 1))
    start = core.now_s()
    run(runner, 2e-3)
    off_ms = float(state(runner)["bridge_off_at_ms"])
    assert off_ms == pytest.approx(start * 1000, abs=core.cpi / core.hz * 1000 * 2)
    assert board.tim.get("CCER") == 0 and board.tim.duty() is None


def test_a_frame_below_the_stack_bottom_overwrites_the_guard_word(runner):
    board = runner.boards[0]
    core = board.core
    _, bottom = board.injector.facts
    core.wr32(bottom, 0x5AFE6A4D)  # where the firmware will keep its guard
    assert runner.command("inject 1 stack") == "ok"
    assert run(runner, 0.05, lambda: core.rd32(bottom) != 0x5AFE6A4D)
    back, low, by = board.injector.lowered or (None, bottom + 8, None)
    assert low == bottom + 8 and state(runner)["injected"].split(",")[2] == "stack:1"


def test_the_m3_mpu_guarding_the_stack_bottom_faults_at_the_push(runner):
    board = runner.boards[0]
    core = board.core
    if not core.v7m:
        pytest.skip("the M0 has no MPU")
    poll, bottom = board.injector.facts
    mpu.configure(core, {0: (bottom, mpu.no_access())}, mpu.CTRL_ENABLE | mpu.CTRL_PRIVDEFENA)  # 32 bytes
    core.wr32(SCB_SHCSR, 1 << 16)  # MEMFAULTENA
    runner.command("inject 1 stack")
    faulted(runner)
    assert core.reg(arm.UC_ARM_REG_IPSR) == 4 and taken(runner).get(4) == 1
    assert poll <= core.fault_pc < poll + 8  # its entry's push
    assert core.rd32(SCB_CFSR) & (DACCVIOL | MMARVALID) == DACCVIOL | MMARVALID
    assert bottom <= core.rd32(SCB_MMFAR) < bottom + 32
    assert core.rd32(SCB_CFSR) & MSTKERR  # the entry's own frame reached the guard too
    assert core.mpu_faults >= 1


def test_a_hung_main_loop_runs_interrupts_until_the_watchdog(runner):
    board = runner.boards[0]
    core = board.core
    assert runner.command("inject 1 hang") == "ok"
    assert run(runner, 0.01, lambda: core.spin_at != 0)
    ticks = taken(runner)[15]
    run(runner, 0.05)
    assert taken(runner)[15] > ticks + 40  # SysTick still taken every millisecond
    assert core.reg(arm.UC_ARM_REG_PC) & ~1 == core.spin_at and board.resets["watchdog"] == 0
    bites_s = board.iwdg.bites_s
    assert bites_s - board.iwdg.kicked_s == pytest.approx(WATCHDOG_S)
    assert run(runner, 0.2, lambda: board.resets["watchdog"] == 1)
    assert bites_s <= runner.now_s < bites_s + 1e-3
    assert core.spin_at == 0  # the reset ends it


def test_a_brownout_resets_with_porrstf_and_keeps_ram_a_powercycle_zeroes_it(runner):
    board = runner.boards[0]
    core = board.core
    _, bottom = board.injector.facts
    core.wr32(bottom, 0x12345678)
    core.wr32(bottom + 4, 0x9ABCDEF0)
    assert runner.command("brownout 1 2") == "ok"
    assert board.rcc.get("CSR") & 0xFF000000 == PORRSTF | PINRSTF
    assert core.rd32(bottom) == 0x12345678 and core.rd32(bottom + 4) == 0x9ABCDEF0
    assert board.resets["power"] == 2 and state(runner)["brownouts"] == "1"
    run(runner, 0.5, lambda: board.in_application())
    assert core.rd32(bottom + 4) == 0x9ABCDEF0  # the bootloader and start-up left it
    # RMVF clears the flags (RM0008 7.3.10, RM0360 6.4.10): a store of it, as the firmware will.
    snippet = bottom + 0x100
    core.write(snippet, bytes.fromhex("0160" "fee7"))  # str r1, [r0]; b .
    core.set_regs((arm.UC_ARM_REG_R0, arm.UC_ARM_REG_R1, arm.UC_ARM_REG_PC),
                  (board.rcc.addr("CSR"), RMVF, snippet | 1))
    run(runner, 1e-3)
    assert board.rcc.get("CSR") & 0xFF000000 == 0 and state(runner)["reset_flags"] == f"{board.rcc.get('CSR'):#010x}"
    assert runner.command("powercycle 1") == "ok"
    assert core.rd32(bottom + 4) == 0
    assert board.rcc.get("CSR") & 0xFF000000 == PORRSTF | PINRSTF


def test_inject_and_brownout_refuse_what_they_do_not_take(runner):
    assert runner.command("inject 1 nosuch").startswith("error: inject takes")
    assert runner.command("inject 7 bus") == "error: no servo holds that ID"
    assert runner.command("inject bus").startswith("error: inject takes")
    assert runner.command("brownout 1 0").startswith("error: brownout takes")
    assert runner.command("brownout 1 x").startswith("error: brownout takes")


@pytest.mark.parametrize("board", BOARDS)
def test_through_the_control_port_a_hang_ends_in_a_watchdog_reset(tmp_path, board):
    """The same commands to a vboard process, as a client sends them."""
    sim = start(tmp_path, board)
    try:
        assert sim.control("inject 1 hang").startswith("ok")
        sim.sleep(0.3)
        s = sim.state(1)
        assert s["resets_watchdog"] == 1 and s["injected"] == "bus:0,undef:0,stack:0,hang:1"
        assert s["reset_flags"] & (IWDGRSTF | PINRSTF) == IWDGRSTF | PINRSTF
        assert s["fault_at_ms"] == "none" and s["bridge_off_at_ms"] == "none"  # a hang is no fault
        assert sim.control("brownout 1 5").startswith("ok")
        s = sim.state(1)
        assert s["brownouts"] == 1 and s["last_reset"] == "power"
        assert s["reset_flags"] & 0xFF000000 == PORRSTF | PINRSTF
    finally:
        sim.stop()
