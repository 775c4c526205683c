"""The virtual boards publish their clock as servo_sim does (tools/vboard/
clock_file.py, firmware/boards/host_sim/sim_clock.h): a 16-byte file in the
state folder that the host reads without asking, and in which a test's host
writes the bus time it waits for (Simulator(fast=True)); the file goes when
the board stops. Time is the board's simulated time."""
from servoctl.servo import Servo
from servoctl.sim import Simulator


def test_the_boards_clock_is_published_and_a_fast_host_waits_on_it(tmp_path):
    state = tmp_path / "state"
    with Simulator(ids=[1], state_dir=str(state), board="stm32f030k6", fast=True) as sim:
        assert sim._clock_map is not None, "the board published no clock file"
        assert (state / "bus.clock").stat().st_size == 32  # the clock, the host's wait, its bytes
        # In whole microseconds, as both publish it: in seconds, ms/1000 and
        # us/1e6 of one instant differ in the last bit about half the time,
        # and a board a loaded PC did not step between the three looks failed.
        start_us = round(sim.clock_s() * 1e6)
        asked_us = round(float(sim.control("clock").split()[0].split("=")[1]) * 1000)
        assert start_us <= asked_us <= round(sim.clock_s() * 1e6), (start_us, asked_us)
        start = sim.clock_s()
        assert sim._clock_conn is None, "the clock was asked for on the control port"
        sim.sleep(1.0)  # the board runs ahead to it
        # In whole µs: 1.378 - 0.378 is 0.9999999999999999 in binary floating point.
        assert round(sim.clock_s() * 1e6) - round(start * 1e6) >= 1_000_000
        with sim.bus(timeout=0.3) as bus:  # a bus that waits for answers tells the board so
            servo = Servo(bus, 1)
            servo.write("soft_start_on", 0)
            servo.move(300, interval_ms=400)
            sim.wait_until(lambda: abs(servo.angle() - 300) <= 2, 1.0)
        assert sim.state(1)["collisions"] == 0
    assert not (state / "bus.clock").exists()  # a board stopped (SIGTERM) removes it


def test_the_clock_is_published_before_ready(tmp_path):
    """The board's power-up (its bootloader's window, the application's
    start) is simulated time before `ready`: the file says so by then. It
    read 0 until the loop's first slice, so a host's first look put its
    reply window's end in the past (a write at the start of a fast test
    met NoReply at once, 1 of 15 starts)."""
    import argparse
    import struct

    from vboard.run import Runner

    args = argparse.Namespace(board="stm32f030k6", id=[1], tcp=0, link=None, host_link="usb",
                              state=str(tmp_path / "state"), supply=None, plant=None, ambient=25.0, app=None,
                              clock="wall")
    runner = Runner(args)
    try:
        runner.power_up()
        published = struct.unpack("<Q", (tmp_path / "state" / "bus.clock").read_bytes()[:8])[0]
        assert published == round(runner.now_s * 1e6) and runner.now_s >= 0.1, (published, runner.now_s)
    finally:
        runner.bus.close()
        runner.control.close()
        runner.clock.close()
