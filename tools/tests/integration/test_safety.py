"""The servo when its host is not there, on the simulator (docs/safety.md):
the bus watchdog's reaction time whatever the other servos hear, the
winding's estimate against the simulator's true winding, a hot duty cycle
that derating lets finish, the fault history across a power cycle, a
DriveDuty whose host falls silent, and ClearFaults on a full page while the
output is driven. Every time here is the simulator's."""

from servoctl import group
from servoctl.errors import Refused
from servoctl.cli import main
from servoctl.servo import MotionSnapshot, Servo

from tests.integration.conftest import _start, finish
from tests.store_pages import (a_clear_is_refused_on_a_full_page, fault_record,
                               released_a_clear_is_taken)

OVER_TEMPERATURE = 128


def test_the_watchdog_acts_within_two_ticks_whatever_the_others_hear(sim3):
    with sim3.bus(timeout=0.2) as bus:
        s1, s2, s3 = (Servo(bus, i) for i in (1, 2, 3))
        s1.write("soft_start_on", 0)
        s1.write("watchdog_action", 2)  # release
        s1.write("watchdog_ms", 100)
        s1.move(angle_decideg=300, interval_ms=60)  # the last frame for servo 1
        end = sim3.clock_s() + 0.4
        while sim3.clock_s() < end:  # the others are spoken to all the while
            s2.ping()
            s3.monitor()
            # A second for the round, as the virtual boards' sync test has
            # (docs/testing.md): this test times the watchdog, not the round.
            assert set(group.sync_monitor(bus, [2, 3], timeout_s=1.0)) == {2, 3}
        state = sim3.state(1)
        silent_ms = state["coasted_ms"] - state["heard_ms"]
        print(f"servo 1 let go {silent_ms:.2f} ms after its last frame (watchdog 100 ms)")
        # Counted in 1 ms ticks from the tick that saw the frame: within 2
        # ticks after the timeout, and up to a tick before it where that tick
        # waited for the request's end (docs/safety.md, "When").
        assert 99.0 <= silent_ms <= 102.0
        assert s1.read("limiter") == MotionSnapshot.LIMITERS.index("watchdog")
        assert s1.read_motion().limiter == "watchdog"
        assert s1.read_fault(0).kind == "watchdog"
        assert not sim3.state(2)["coasted_ms"] and not sim3.state(3)["coasted_ms"]
        s1.move(angle_decideg=0, interval_ms=60)  # the next motion command clears it
        assert s1.read("limiter") != MotionSnapshot.LIMITERS.index("watchdog")


def test_the_winding_estimate_follows_the_true_winding(servo, sim):
    """A stall against a hard stop at the power limit heats the winding
    (12 s) far faster than the case (612 s); then it cools, released."""
    servo.write("power_limit", 20000)  # full duty: 2.7 A, 20 W into the winding
    servo.write("stall_power", 20000)
    sim.control("stop 20")
    servo.move(angle_decideg=900, interval_ms=200)
    worst, hottest = 0.0, 0.0
    for phase in ("stalled", "released"):
        if phase == "released":
            servo.stop("release")
        for _ in range(12):
            sim.sleep(2.0)
            st = sim.state(1)
            worst = max(worst, abs(st["winding_estimate"] - st["winding"]))
            hottest = max(hottest, st["winding"])
        print(f"{phase}: winding {st['winding']:.1f} degC, estimate {st['winding_estimate']:.1f}, "
              f"case {st['case']:.1f}")
    print(f"worst estimate error {worst:.2f} degC; the winding rose to {hottest:.1f} degC")
    assert hottest > 65.0  # 40 K of heating, or the test proves nothing
    assert worst <= 5.0
    assert st["winding"] < hottest - 10.0  # it did cool


def _squeeze(servo, sim, cycles: int) -> dict:
    """A gripper's duty cycle against a stop at 20 deg: squeeze 2 s at full
    duty, open 1 s; the hottest winding and case, and whether the
    temperature protection tripped."""
    hottest, tripped = 0.0, False
    for _ in range(cycles):
        servo.move(angle_decideg=900, interval_ms=100)
        sim.sleep(2.0)
        servo.move(angle_decideg=0, interval_ms=100)
        sim.sleep(1.0)
        st = sim.state(1)
        hottest = max(hottest, st["winding"])
        tripped |= bool(st["status"] & OVER_TEMPERATURE)
    return {"winding": hottest, "tripped": tripped, "case": st["case"]}


def test_a_hot_duty_cycle_finishes_derated(tmp_path):
    """At 40 degC ambient, soaked to 74 degC: without derating (item 66 = 0,
    the maker's servo) the squeezing trips the temperature protection; with
    it, the same cycles finish at less force, the winding under its limit."""
    results = {}
    for derating in (0, 1):
        (tmp_path / f"derating{derating}").mkdir()
        sim = _start(tmp_path / f"derating{derating}", [1])
        try:
            with sim.bus(timeout=0.2) as bus:
                servo = Servo(bus, 1)
                servo.write("soft_start_on", 0)
                servo.write("derating", derating)
                servo.write("power_limit", 25000)  # full duty: 20 W into a squeezing winding
                servo.write("stall_power", 25000)
                sim.control("stop 20")
                sim.control("soak 74")
                sim.control("ambient 40")
                results[derating] = _squeeze(servo, sim, 8)
                results[derating]["faults"] = [f.kind for f in servo.faults()]
        finally:
            finish(sim, [1])
        print(f"derating {derating}: {results[derating]}")
    assert results[0]["tripped"] and "over_temperature" in results[0]["faults"]
    assert not results[1]["tripped"] and "over_temperature" not in results[1]["faults"]
    assert results[1]["winding"] < 125.0


def test_faults_are_read_back_in_order_after_a_power_cycle(sim, capsys):
    sim.control("supply 3500")  # below 39
    sim.sleep(0.3)
    sim.control("supply 7400")
    sim.sleep(0.5)
    sim.control("supply 9000")  # above 40
    sim.sleep(0.3)
    sim.control("supply 7400")
    sim.sleep(0.5)
    sim.control("powercycle")
    sim.sleep(0.5)  # the bootloader hands over to the application
    with sim.bus(timeout=0.2) as bus:
        faults = Servo(bus, 1).faults()
    assert [f.kind for f in faults] == ["high_voltage", "low_voltage"]
    assert faults[0].number > faults[1].number and faults[0].voltage_mv > 8400 > 4000 > faults[1].voltage_mv
    assert all(240 < f.winding_decic < 260 and 240 < f.case_decic < 260 for f in faults)  # 25 degC
    assert main(["--port", sim.url, "faults", "1"], clock=sim.clock_s) == 0
    out = capsys.readouterr().out
    assert "high_voltage" in out and "low_voltage" in out and "check the supply" in out
    assert main(["--port", sim.url, "faults", "1", "--clear"], clock=sim.clock_s) == 0
    sim.sleep(0.1)
    sim.control("powercycle")
    sim.sleep(0.5)
    with sim.bus(timeout=0.2) as bus:
        assert Servo(bus, 1).faults() == []


def test_the_watchdog_stops_a_duty_when_the_host_falls_silent(sim, servo):
    """DriveDuty counts as driven: a host that dies mid-identify
    no longer leaves the bridge driven for up to 10 s."""
    servo.write("watchdog_action", 2)  # release
    servo.write("watchdog_ms", 100)
    servo.drive_duty(0.3, 10000)  # the last frame but ReadMotion
    sim.sleep(0.05)
    snap = servo.read_motion()
    assert not snap.flags & snap.RELEASED and snap.duty_q15 != 0
    sim.sleep(0.3)
    state = sim.state(1)
    silent_ms = state["coasted_ms"] - state["heard_ms"]
    print(f"the duty stopped {silent_ms:.2f} ms after the last frame (watchdog 100 ms)")
    assert 100.0 <= silent_ms <= 102.0
    snap = servo.read_motion()
    assert snap.flags & snap.RELEASED and snap.limiter == "watchdog"
    assert servo.read_fault(0).kind == "watchdog"


SLOTS = 32  # a page's records: 1024-byte pages (servo_sim) of 32-byte records


def _history_with_one_slot_left() -> bytes:
    """Page 1 full of faults 1-32 (the 15 older of the 16 shown); page 0 in
    use with its slots but the last spent (failed programs) and fault 40 in
    slot 30. The spare still shows faults, so no erase is due at power-up."""
    page0 = bytes(30 * 32) + fault_record(40, 6) + b"\xff" * 32
    page1 = b"".join(fault_record(n, 2) for n in range(1, SLOTS + 1))
    return page0 + page1


def test_a_clear_on_a_full_page_while_driven_is_refused_then_taken(tmp_path, capsys):
    """The fault page fills while the output is held: the spare page waits
    for the output released and a quiet bus (a page erase stalls the CPU),
    and a ClearFaults meanwhile is refused, where it was answered "done"
    and then neither applied nor kept. Released, it is taken."""
    (tmp_path / "state").mkdir()
    (tmp_path / "state" / "servo-1.faults").write_bytes(_history_with_one_slot_left())
    sim = _start(tmp_path, [1])
    try:
        with sim.bus(timeout=0.2) as bus:
            a_clear_is_refused_on_a_full_page(Servo(bus, 1), sim)
        assert main(["--port", sim.url, "faults", "1", "--clear"], clock=sim.clock_s) == Refused.exit_code
        assert "page is full while the output is driven" in capsys.readouterr().err
        with sim.bus(timeout=0.2) as bus:
            released_a_clear_is_taken(Servo(bus, 1), sim, "powercycle")
    finally:
        finish(sim, [1])
