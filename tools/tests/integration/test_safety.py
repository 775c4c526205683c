"""The servo when its host is not there, on the simulator (docs/safety.md):
the bus watchdog's reaction time whatever the other servos hear, the
winding's estimate against the simulator's true winding, a hot duty cycle
that derating lets finish, and the fault history across a power cycle.
Every time here is the simulator's."""
from servoctl import group
from servoctl.cli import main
from servoctl.servo import MotionSnapshot, Servo

from tests.integration.conftest import _start, finish

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
        assert 100.0 <= silent_ms <= 102.0
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
