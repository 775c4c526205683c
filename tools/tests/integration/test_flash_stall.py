"""Issue 10: a config save costs no byte and no tick.

The simulator stalls a servo's CPU for every flash operation the firmware
makes, as the STM32F1 does (it runs from the flash it writes): 40 ms a
page erase, 70 us a half-word (DS5319's longest times). Nothing runs
meanwhile, no main loop, no control tick, no interrupt: bytes go on into
the DMA ring of the reference board's port, while a port that takes each
byte in its receive interrupt overruns. Two servos share a 1 Mbaud bus;
the host writes a changed setting to servo 1 a thousand times while it
turns in wheel mode, and reads servo 2's monitor in between, so bytes are
on the wire while servo 1 programs its saves."""
from servoctl.protocol import Bus, NoReply
from servoctl.servo import Servo
from servoctl.sim import Simulator

WRITES = 1000
BAUD_INDEX_1M = 8


def write_while_moving(tmp_path, rx, writes, run=0):
    """Servo 1's state after `writes` config writes at 1 Mbaud while it
    turns, and the writes that were answered."""
    sim = Simulator(ids=[1, 2], state_dir=str(tmp_path / f"{rx}-{run}"), rx=rx)
    sim.start()
    try:
        with sim.bus(timeout=0.2) as bus:
            for i in (1, 2):
                Servo(bus, i).write("baud", BAUD_INDEX_1M)  # answered at 115200
        sim.control("hostbaud 1000000")
        with sim.bus(baud=1000000, timeout=0.2) as bus:
            one, two = Servo(bus, 1), Servo(bus, 2)
            one.write("soft_start_on", 0)
            before = sim.state(1)
            one.wheel("run", speed_dps=90)
            answered = 0
            try:
                for n in range(writes):
                    one.write("current_limit", 3000 + n % 2)  # a change every time
                    answered += 1
                    two.monitor()
            except NoReply:
                pass  # a request lost: counted by `answered`
            assert abs(sim.state(1)["velocity"]) > 45, "servo 1 stopped turning"
        return before, sim.state(1), answered
    finally:
        err = sim.stop()
        assert "runtime error" not in err and "AddressSanitizer" not in err, err


def test_a_thousand_writes_cost_no_byte_and_no_tick(tmp_path):
    before, after, answered = write_while_moving(tmp_path, "dma", WRITES)
    assert answered == WRITES
    assert after["saves"] > before["saves"], "no save ran: the test proves nothing"
    assert after["flash_stall_ms"] > before["flash_stall_ms"]
    assert after["dropped_ticks"] == 0
    assert after["rx_overruns"] == 0
    assert after["rx_lost"] == 0
    assert after["collisions"] == 0


def test_a_port_without_dma_would_lose_bytes(tmp_path):
    """The model bites: the same traffic with a byte per receive interrupt
    overruns while a half-word programs (70 us, 7 bytes at 1 Mbaud). Bytes
    must be on the wire during a program step for that; a simulator that
    falls behind the wall clock (a loaded machine) catches up with none in
    flight, so up to three runs are given."""
    for attempt in range(3):
        _, after, _ = write_while_moving(tmp_path, "interrupt", WRITES, attempt)
        if after["rx_overruns"] > 0:
            return
    raise AssertionError("no overrun in three runs: the flash stall model does not bite")


def test_an_answer_that_would_leave_late_is_dropped_and_counted(tmp_path, capsys):
    """A request that lands in a config-store page erase (40 ms, the line
    quiet for 100 ms before it) is carried out, but not answered late: the
    host gets no answer, and ReadStore, and `servoctl store`, count it. A
    host cannot time its request into the erase exactly, so the test tries
    until one lands there, and checks every round that a missing answer is
    counted and an answered one is not."""
    import json

    from servoctl.cli import main

    sim = Simulator(ids=[1], state_dir=str(tmp_path / "state"))
    sim.start()
    try:
        with sim.bus(timeout=0.2) as bus:
            one = Servo(bus, 1)
            landed, n = 0, 0
            for _ in range(6):
                # Records until one starts the other page: the old page is
                # then erased ahead once the line is quiet for 100 ms.
                while True:
                    n += 1
                    one.write("current_limit", 3000 + n % 2)
                    sim.sleep(0.07)  # saved 50 ms after the change
                    state = sim.state(1)
                    if state["saves"] % 21 == 1 and state["saves"] > 1:
                        answered_at = state["last_sent_ms"] / 1000.0  # simulated time
                        break
                stalled = sim.state(1)["flash_stall_ms"]
                # Into the erase that starts 100 ms after the last answer.
                sim.sleep(answered_at + 0.12 - sim.clock_s())
                answered = one.ping(timeout=0.2)
                sim.sleep(0.1)
                erased = sim.state(1)["flash_stall_ms"] - stalled >= 40.0
                dropped = one.read_store().answers_dropped
                assert erased, "no erase ran: the test proves nothing"
                assert dropped == landed + (not answered), (answered, dropped, landed)
                landed = dropped
                if landed:
                    break
            assert landed >= 1, "no request landed in an erase in six rounds"
        assert main(["--port", sim.url, "store", "1", "--json"], clock=sim.clock_s) == 0
        report = json.loads(capsys.readouterr().out)
        assert report["answers_dropped"] == landed and report["bytes_lost"] == 0
        assert sim.state(1)["collisions"] == 0
    finally:
        err = sim.stop()
        assert "runtime error" not in err and "AddressSanitizer" not in err, err
