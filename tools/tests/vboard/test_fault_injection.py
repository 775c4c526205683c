"""The servo's own faults injected into the shipped images on both virtual
boards (vboard/inject.py, the control port's inject and brownout), taken
as the architecture says (the exception number; on the Cortex-M3 the
CFSR/HFSR bits and the fault address, ARMv7-M ARM B3.2.15-B3.2.19; the
stacked PC the faulting instruction), and what the firmware does about
them: the bridge off within microseconds of the faulting instruction, the
record kept in RAM across the reset it asks for (ports/stm32_common/
kept_ram.h), read back by the next start. Runs in this process (the
runner's control-port commands, as a client's); every time is the boards'
simulated time. What the servo then answers on the bus: test_own_faults_bus.py."""
import struct

import pytest
from unicorn import arm_const as arm

from vboard import bench
from vboard.faults import BFARVALID, DACCVIOL, MMARVALID, PRECISERR, SCB_SHCSR, UNDEFINSTR
from vboard.idle_skip import _elf, _symbol

from .test_virtual_boards import BOARDS, start

PORRSTF, PINRSTF = 1 << 27, 1 << 26  # RCC_CSR (RM0008 7.3.10; RM0360, RCC_CSR; RM0444 5.4.26: PWRRSTF)


def watchdog_s(board) -> float:
    """The firmware's IWDG period: 72 ms of counts at the LSI / 4 (RLR 720 at
    40 kHz, the F0/F1's; 576 at 32 kHz, the G0's: board_common.h,
    stm32g0_regs.h), as (RLR + 1) counts (timers.py)."""
    lsi = board.part_facts["lsi_hz"]
    return (72 * lsi // 4000 + 1) * 4 / lsi


# The time from the faulting instruction to the bridge off the firmware must
# keep: 5 us on the F103, 10 us on the F030 (docs/safety.md).
BRIDGE_OFF_S = {True: 5e-6, False: 10e-6}
FORCED = 0x80  # the record's usage byte: HFSR FORCED (hal/hal_reset.h)
KIND_FIRMWARE, KIND_WATCHDOG, KIND_BROWN_OUT = 10, 11, 13


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


def kept(board) -> dict:
    """The record the firmware keeps in RAM across a reset (kept_ram.h:
    magic, then struct hal_reset, then its note)."""
    address = _symbol(_elf(board.injector_elf), "_kept_ram")[0]
    raw = bytes(board.core.uc.mem_read(address, 36))
    kind, in_row, counts = raw[4], raw[5], list(raw[8:12])
    pc, lr, sp_offset, mm_bus, exception, usage = struct.unpack_from("<IIHHBB", raw, 12)
    return {"magic": raw[:4], "kind": kind, "in_row": in_row, "counts": counts, "pc": pc, "lr": lr,
            "mm_bus": mm_bus, "exception": exception, "usage": usage}


def handled(runner, exception: int):
    """The fault taken as exception, the bridge off in time, the chip reset
    by the firmware and started again: the core."""
    board = runner.boards[0]
    core = faulted(runner)
    fault_at = core.fault_at_s
    assert run(runner, 0.05, lambda: board.resets["software"] == 1)
    assert taken(runner).get(exception) == 1
    off_s = float(state(runner)["bridge_off_at_ms"]) / 1000
    assert 0 <= off_s - fault_at <= BRIDGE_OFF_S[core.v7m]
    assert run(runner, 0.5, lambda: board.in_application())
    return core


def test_a_bus_error_on_a_register_the_main_loop_reads(runner):
    board = runner.boards[0]
    assert runner.command("inject 1 bus") == "ok"
    v7m = board.core.v7m
    core = handled(runner, 5 if v7m else 3)  # the firmware takes BusFault as its own
    record = kept(board)
    assert record["kind"] == KIND_FIRMWARE and record["pc"] == core.fault_pc
    assert record["exception"] == (5 if v7m else 3) and record["counts"][0] == 1 and record["in_row"] == 1
    if v7m:
        assert record["mm_bus"] == (PRECISERR | BFARVALID) & 0xFFFF
    s = state(runner)
    assert s["injected"].startswith("bus:1") and s["inject_armed"] == "none"


def test_a_fault_not_enabled_is_escalated_and_recorded_so(runner):
    core = runner.boards[0].core
    if not core.v7m:
        pytest.skip("ARMv6-M has HardFault only")
    core.wr32(SCB_SHCSR, 0)  # as a firmware that leaves BusFault disabled
    runner.command("inject 1 bus")
    handled(runner, 3)
    record = kept(runner.boards[0])
    assert record["exception"] == 3 and record["usage"] & FORCED
    assert record["mm_bus"] == (PRECISERR | BFARVALID) & 0xFFFF


def test_an_undefined_instruction_in_thread_mode(runner):
    board = runner.boards[0]
    assert runner.command("inject 1 undef") == "ok"
    v7m = board.core.v7m
    core = handled(runner, 6 if v7m else 3)
    assert board.h["BOARD_SLOT_BASE"] <= core.fault_pc < board.h["BOARD_CONFIG_PAGE0"]
    record = kept(board)
    assert record["pc"] == core.fault_pc and record["exception"] == (6 if v7m else 3)
    if v7m:
        assert record["usage"] & 1 == UNDEFINSTR >> 16


def test_a_stack_that_reaches_its_bottom(runner):
    """The M3's MPU region faults at the push that enters it; the M0's
    guard word is found overwritten by the next control tick's check."""
    board = runner.boards[0]
    core = board.core
    assert runner.command("inject 1 stack") == "ok"
    if core.v7m:
        handled(runner, 4)
        record = kept(board)
        assert record["exception"] == 4
        assert record["mm_bus"] & (DACCVIOL | MMARVALID) == DACCVIOL | MMARVALID
        assert core.mpu_faults >= 1
    else:
        assert run(runner, 0.05, lambda: board.resets["software"] == 1)
        assert board.duty is None
        assert run(runner, 0.5, lambda: board.in_application())
        record = kept(board)
        assert record["exception"] == 0 and record["kind"] == KIND_FIRMWARE  # the guard, not an exception
    assert state(runner)["injected"].split(",")[2] == "stack:1"


def test_a_hung_main_loop_runs_interrupts_until_the_watchdog(runner):
    board = runner.boards[0]
    core = board.core
    assert runner.command("inject 1 hang") == "ok"
    assert run(runner, 0.01, lambda: core.spin_at != 0)
    ticks = taken(runner)[15]
    run(runner, 0.03)
    assert taken(runner)[15] > ticks + 20  # SysTick still taken every millisecond
    assert core.reg(arm.UC_ARM_REG_PC) & ~1 == core.spin_at and board.resets["watchdog"] == 0
    bites_s = board.iwdg.bites_s
    assert bites_s - board.iwdg.kicked_s == pytest.approx(watchdog_s(board))
    assert run(runner, 0.2, lambda: board.resets["watchdog"] == 1)
    assert bites_s <= runner.now_s < bites_s + 1e-3 and board.duty is None  # the reset let the bridge go
    assert core.spin_at == 0  # the reset ends it
    assert run(runner, 0.5, lambda: board.in_application())
    assert kept(board)["kind"] == KIND_WATCHDOG


def test_a_brownout_keeps_ram_so_the_start_tells_it_from_a_power_on(runner):
    board = runner.boards[0]
    assert runner.command("brownout 1 2") == "ok"
    assert board.resets["power"] == 2 and state(runner)["brownouts"] == "1"
    assert run(runner, 0.5, lambda: board.in_application())
    record = kept(board)
    assert record["kind"] == KIND_BROWN_OUT and record["counts"][3] == 1 and record["in_row"] == 0
    assert board.rcc.get("CSR") & 0xFF000000 == 0  # the firmware read the flags and cleared them (RMVF)
    assert runner.command("powercycle 1") == "ok"
    assert board.rcc.get("CSR") & 0xFF000000 == PORRSTF | PINRSTF
    assert run(runner, 0.5, lambda: board.in_application())
    record = kept(board)
    assert record["kind"] == 0 and record["counts"] == [0, 0, 0, 0]  # RAM lost: a power-on


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
        assert s["last_reset"] == "watchdog"
        assert s["fault_at_ms"] == "none" and s["hung_at_ms"] != "none"  # a hang is no exception
        assert sim.control("brownout 1 5").startswith("ok")
        s = sim.state(1)
        assert s["brownouts"] == 1 and s["last_reset"] == "power"
    finally:
        sim.stop()
