"""The host's side of the simulators is a USB-serial adapter, as on every
real host (firmware/boards/host_sim/sim_usb.h, tools/vboard/usb.py,
docs/simulator.md): an answer reaches the host program in a USB packet, not
byte by byte as it ends on the wire; an FTDI chip's latency timer holds it
back; a raw link, for a test that needs the worst case, hands over every
byte alone. And a --link with --tcp is refused, not ignored."""
import os
import select
import subprocess
import sys

import pytest
import serial

from servoctl import protocol as p
from servoctl.sim import Simulator, find_binary

from ..launchers import REPO
from .conftest import finish

BOARDS = [None, "stm32f103"]  # servo_sim, a virtual board
PING_ANSWER = 6  # bytes: header 2, code, size, ID, checksum


def stop(sim, ids, board):
    """Stops the simulator, or the virtual board, and judges what it said."""
    if board is None:
        finish(sim, ids)
        return
    try:
        state = sim.state(ids[0])
    finally:
        sim.stop()
    assert state["collisions"] == 0


def reads_of_answers(sim, count):
    """Pings servo 1 count times through the pty (pyserial sets its rate)
    and returns, for each answer, the sizes of the reads that brought it."""
    with serial.Serial(sim.url, 115200, timeout=0) as port:
        fd = port.fileno()
        sizes = []
        for _ in range(count):
            port.write(p.request_frame(p.PING, bytes([1])))
            got = []
            while sum(got) < PING_ANSWER:
                ready, _, _ = select.select([fd], [], [], 5.0)
                assert ready, f"no answer: {got}"
                got.append(len(os.read(fd, 64)))
            sizes.append(got)
        return sizes


@pytest.mark.parametrize("board", BOARDS)
def test_an_answer_reaches_the_host_in_one_usb_packet(tmp_path, board):
    """servo_sim used to write each byte to the pty as it ended on the wire:
    the host read an answer in pieces (1, 5, 1, 2 ... bytes), which no USB
    adapter does, and which the maker's SDK cannot read. Behind the
    simulated adapter every answer arrives whole."""
    sim = Simulator(ids=[1], tcp=False, board=board, state_dir=str(tmp_path / "state")).start()
    try:
        sizes = reads_of_answers(sim, 40)
    finally:
        stop(sim, [1], board)
    assert sizes == [[PING_ANSWER]] * 40


def test_a_raw_link_hands_over_each_byte_and_servoctl_still_reads_it(tmp_path):
    """--host-link raw, the worst case of a host's reader: servoctl puts an
    answer together from whatever pieces it gets."""
    sim = Simulator(ids=[1, 2], host_link="raw", state_dir=str(tmp_path / "state")).start()
    try:
        with sim.bus(timeout=0.2) as bus:
            for i in range(40):
                assert bus.request(p.PING, bytes([1 + i % 2]))
    finally:
        finish(sim, [1, 2])


@pytest.mark.parametrize("board", BOARDS)
def test_an_ftdi_latency_timer_holds_answers_back(tmp_path, board):
    """--host-link ftdi: the chip hands over an answer shorter than its 62
    bytes only when its 16 ms latency timer runs out (FTDI AN232B-04), so a
    ping takes 8 ms on average, and up to 17, of simulated time: every
    answer waits for it, none is lost."""
    sim = Simulator(ids=[1], host_link="ftdi", board=board, state_dir=str(tmp_path / "state")).start()
    try:
        with sim.bus(timeout=0.2) as bus:
            took = []
            for _ in range(20):
                before = sim.clock_s()
                assert bus.request(p.PING, bytes([1]))
                took.append(sim.clock_s() - before)
    finally:
        stop(sim, [1], board)
    assert sum(took) / len(took) > 0.004, took


def run(program, tmp_path, *args):
    """servo_sim or a virtual board with args; killed if it has not exited
    within 20 s (one that runs has taken the arguments)."""
    if program == "servo_sim":
        cmd = [str(find_binary())]
    else:
        cmd = [sys.executable, "-m", "vboard", "--board", "stm32f103"]
    env = dict(os.environ, PYTHONPATH=str(REPO / "tools"))
    return subprocess.run(cmd + ["--state", str(tmp_path / "state"), *args], capture_output=True,
                          text=True, timeout=20, env=env)


@pytest.mark.parametrize("program", ["servo_sim", "vboard"])
def test_a_link_with_a_tcp_bus_is_refused(tmp_path, program):
    """servo_sim --tcp P --link PATH printed 'link PATH' and made no link:
    a pseudo-terminal's link has no pseudo-terminal on a TCP bus."""
    link = tmp_path / "servo"
    done = run(program, tmp_path, "--tcp", "0", "--link", str(link))
    assert done.returncode == 2, done
    assert "--link" in done.stderr and "--tcp" in done.stderr, done.stderr
    assert "link" not in done.stdout and not os.path.lexists(link)


@pytest.mark.parametrize("program", ["servo_sim", "vboard"])
def test_an_adapter_that_is_none_is_refused(tmp_path, program):
    done = run(program, tmp_path, "--host-link", "ftdi:0")
    assert done.returncode == 2 and "--host-link is usb, ftdi, ftdi:MS (1 to 255) or raw" in done.stderr, done
