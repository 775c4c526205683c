"""servobus's host examples (tools/servobus/examples, docs/c-library.md)
against servo_sim: the ros2_control-style read()/write() cycle in C++, and
the C robot loop of scripts/c_loop_bench.sh. Both wait on the simulator's
clock (its file, state_dir/bus.clock): a loaded PC slows them, it does not
fail them. The simulator follows the wall clock (REAL_TIME): the examples
pace themselves on it. The robot loop's tests judge its cycles on a paced
simulator (sb_loop_bench ... paced): it runs only while the loop waits, so
what the loop's host does, or a loaded PC keeps it from, costs no
simulated time."""
import subprocess
from pathlib import Path

from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..launchers import REPO
from .conftest import _start, finish

REAL_TIME = True
EXAMPLES = REPO / "build" / "host" / "tools" / "servobus"


def _run(args, timeout=120):
    """An example, stopped whatever happens (subprocess.run kills it on a timeout)."""
    return subprocess.run([str(EXAMPLES / args[0]), *args[1:]], capture_output=True, text=True, timeout=timeout)


def _where(sim):
    return sim.url.removeprefix("socket://"), str(Path(sim.state_dir) / "bus.clock")


def _paced_sim(tmp_path, ids):
    folder = tmp_path / f"paced{len(list(tmp_path.glob('paced*')))}"
    folder.mkdir()
    return _start(folder, ids, paced=True)


def _paced_loop(tmp_path, ids, cycles, unplugged=None):
    """sb_loop_bench's words on a fresh paced simulator (the paced host
    must be the simulator's first), with servo unplugged silent."""
    sim = _paced_sim(tmp_path, ids)
    try:
        if unplugged is not None:
            assert sim.control(f"unplug 1 {unplugged}").strip() == "ok"
        clock = _where(sim)[1]  # the bus as servo_sim prints it, socket:// and all
        done = _run(["sb_loop_bench", sim.url, clock, "115200", str(len(ids)), str(cycles), "paced"])
    finally:
        finish(sim, ids)
    assert done.returncode == 0, done.stdout + done.stderr
    return dict(zip(*[iter(done.stdout.split())] * 2))


def test_the_ros2_control_style_cycle_moves_three_joints(sim3):
    with sim3.bus(timeout=0.2) as bus:
        for i in (1, 2, 3):
            Servo(bus, i).write("soft_start_on", 0)
    address, clock = _where(sim3)
    done = _run(["sb_ros2_cycle", address, "--clock", clock, "--ids", "1,2,3", "--seconds", "1", "--period-ms", "10"])
    assert done.returncode == 0, done.stdout + done.stderr
    assert "cycles 100 joints 3 missed" in done.stdout, done.stdout
    assert "AddressSanitizer" not in done.stderr and "runtime error" not in done.stderr
    assert abs(sim3.state(2)["angle"] - 10.0) < 1.5  # 10 degrees on from 0


def test_the_cycle_refuses_a_joint_resting_outside_its_angle_limits(sim3):
    """Limits of +-90 deg, horn at 130 deg: the cycle streamed from there,
    the servo clamped its setpoint into the limits and threw the horn 40
    deg at top speed. It reads each joint's limits first and refuses,
    naming the servo and its limits; nothing moves."""
    with sim3.bus(timeout=0.2) as bus:
        for i in (1, 2, 3):
            Servo(bus, i).write("soft_start_on", 0)
        s = Servo(bus, 2)
        s.write("angle_limit_on", 0)
        s.move_to(130, speed_dps=200, wait=True)
        s.write("angle_max", 900)
        s.write("angle_min", -900)
        s.write("angle_limit_on", 1)
    at = sim3.state(2)["angle"]
    address, clock = _where(sim3)
    done = _run(["sb_ros2_cycle", address, "--clock", clock, "--ids", "1,2,3", "--seconds", "1", "--period-ms", "10"])
    assert done.returncode == 1, done.stdout + done.stderr
    assert "servo 2 is at 130." in done.stderr and "outside its angle limits -90.0..90.0 deg" in done.stderr, \
        done.stderr
    assert abs(sim3.state(2)["angle"] - at) < 0.5 and abs(sim3.state(2)["velocity"]) < 2  # never streamed
    assert abs(sim3.state(1)["angle"]) < 0.5  # nor the others


def test_the_cycle_keeps_its_commands_within_the_limits(sim3):
    """A joint 5 deg below its upper limit: its 10-deg ramp stops at the
    limit, where the servo holds it, and the cycle ends there (exit 0)."""
    with sim3.bus(timeout=0.2) as bus:
        for i in (1, 2, 3):
            Servo(bus, i).write("soft_start_on", 0)
        Servo(bus, 3).write("angle_max", 50)
    address, clock = _where(sim3)
    done = _run(["sb_ros2_cycle", address, "--clock", clock, "--ids", "1,2,3", "--seconds", "1", "--period-ms", "10"])
    assert done.returncode == 0, done.stdout + done.stderr
    assert abs(sim3.state(3)["angle"] - 5.0) < 1.0 and abs(sim3.state(1)["angle"] - 10.0) < 1.5


def test_the_cycle_refuses_an_id_it_cannot_address_and_an_unknown_option():
    """No servo is opened: the arguments are refused first, naming what is wrong."""
    bad_id = _run(["sb_ros2_cycle", "127.0.0.1:1", "--ids", "1,300"])
    assert bad_id.returncode == 2 and "'300' is not a servo ID (0-254)" in bad_id.stderr, bad_id.stderr
    unknown = _run(["sb_ros2_cycle", "127.0.0.1:1", "--idz", "1"])
    assert unknown.returncode == 2 and "usage:" in unknown.stderr, unknown.stderr
    broadcast = _run(["sb_ros2_cycle", "127.0.0.1:1", "--ids", "255"])
    assert broadcast.returncode == 2 and "'255' is not a servo ID (0-254)" in broadcast.stderr, broadcast.stderr


def test_the_cycle_takes_id_254_and_the_address_servoctl_sim_prints():
    """254 is a servo's ID; socket://HOST:PORT is how servoctl sim prints the
    bus: both taken, up to the connection (no simulator listens at port 1)."""
    done = _run(["sb_ros2_cycle", "socket://127.0.0.1:1", "--ids", "254"])
    assert done.returncode == 1 and "cannot connect to 127.0.0.1:1 (errno " in done.stderr, done.stderr


def test_the_cycle_parses_its_numbers_strictly():
    """A number that is not one, or beyond its range, is refused by name
    (exit 2), not wrapped or read as 0; an empty ID is no ID."""
    for args, why in ((["--seconds", "-1"], "--seconds: '-1' is not a time in seconds"),
                      (["--period-ms", "65536"], "--period-ms: '65536' is not a period of 1-1000 ms"),
                      (["--period-ms", "70000"], "--period-ms: '70000' is not a period of 1-1000 ms"),
                      (["--period-ms", "abc"], "--period-ms: 'abc' is not a period of 1-1000 ms"),
                      (["--ids", "1,,2"], "--ids: '' is not a servo ID (0-254) in '1,,2'")):
        done = _run(["sb_ros2_cycle", "127.0.0.1:1", *args])
        assert done.returncode == 2 and why in done.stderr, (args, done.stderr)


def test_the_cycle_refuses_a_period_shorter_than_the_wire_s_cycle(sim3):
    """1 ms at 115200 baud: a cycle's bytes take longer than the period."""
    address, clock = _where(sim3)
    done = _run(["sb_ros2_cycle", address, "--clock", clock, "--period-ms", "1"])
    assert done.returncode == 1, done.stdout + done.stderr
    assert "1 ms is shorter than the wire's cycle" in done.stderr, done.stderr
    assert "bytes on the wire" in done.stderr and "at 115200 baud" in done.stderr, done.stderr


def test_the_c_robot_loop_names_the_address_it_could_not_reach(tmp_path):
    clock = tmp_path / "bus.clock"
    clock.write_bytes(bytes(32))  # a clock file no simulator writes
    done = _run(["sb_loop_bench", "socket://127.0.0.1:1", str(clock), "115200", "1", "1"])
    assert done.returncode == 2 and "no simulator at socket://127.0.0.1:1\n" in done.stderr, done.stderr


def test_the_c_robot_loop_reads_every_state(tmp_path):
    words = _paced_loop(tmp_path, [1, 2, 3], 40)
    assert words["cycles"] == "40" and words["missed"] == "0", words
    # Its rate against the wire's limit is the benchmark's (docs/c-library.md,
    # real time); paced, a cycle is its bytes on the wire and the servos'
    # turnarounds: never shorter than the wire, and the host costs nothing.
    assert 0.9 < float(words["ratio"]) <= 1.0, words


def test_a_paced_loop_refuses_a_simulator_another_host_has_used(tmp_path):
    """Its byte counts start at zero: on a bus that has carried another
    host's bytes the simulator would wait for bytes that never come."""
    sim = _paced_sim(tmp_path, [1])
    try:
        with sim.bus(timeout=0.2) as bus:
            Servo(bus, 1).ping()
        address, clock = _where(sim)
        done = _run(["sb_loop_bench", address, clock, "115200", "1", "2", "paced"])
    finally:
        finish(sim, [1])
    assert done.returncode == 2 and "a paced host must be its first" in done.stderr, done.stderr


def test_the_bench_and_the_cycle_say_what_is_wrong(tmp_path):
    """A wrong clock file, count or address is named (exit 2), not a crash:
    an empty file was mapped past its end (SIGBUS)."""
    (tmp_path / "empty").write_bytes(b"")
    for clock, why in ((tmp_path / "empty", "is not a simulator's clock file"),
                       (tmp_path / "none", "cannot be opened")):
        for paced in ([], ["paced"]):
            done = _run(["sb_loop_bench", "127.0.0.1:1", str(clock), "115200", "3", "2", *paced])
            assert done.returncode == 2 and why in done.stderr, done.stderr
        cycle = _run(["sb_ros2_cycle", "127.0.0.1:1", "--clock", str(clock)])
        assert cycle.returncode == 2 and why in cycle.stderr, cycle.stderr
    for baud in ("0", "115200x"):
        done = _run(["sb_loop_bench", "127.0.0.1:1", str(tmp_path / "empty"), baud, "3", "2"])
        assert done.returncode == 2 and f"BAUD '{baud}' is not a baud rate" in done.stderr, done.stderr
    done = _run(["sb_loop_bench", "127.0.0.1:1", str(tmp_path / "empty"), "115200", "40", "2"])
    assert done.returncode == 2 and "COUNT must be 1-32" in done.stderr, done.stderr
    done = _run(["sb_loop_bench", "localhost", str(tmp_path / "empty"), "115200", "3", "2"])
    assert done.returncode == 2 and "neither HOST:PORT nor a /dev path" in done.stderr, done.stderr


def test_an_unpaced_loop_on_a_paced_simulator_says_so(tmp_path):
    """Without 'paced' the loop never tells a paced simulator it waits, so
    its clock stands still: after SB_SIM_CLOCK_STALLED_S of the PC's time
    (30 s unless set) it says so and exits 3 (it hung, silent)."""
    import os

    sim = _paced_sim(tmp_path, [1])
    try:
        address, clock = _where(sim)
        done = subprocess.run([str(EXAMPLES / "sb_loop_bench"), address, clock, "115200", "1", "5"],
                              capture_output=True, text=True, timeout=60,
                              env={**os.environ, "SB_SIM_CLOCK_STALLED_S": "1"})
    finally:
        finish(sim, [1])
    assert done.returncode == 3 and "--clock paced and this program does not pace it" in done.stderr, done.stderr


def test_the_serial_transport_on_servo_sims_pseudo_terminal(tmp_path):
    """sb_serial_open (termios raw 8N1; no low-latency mode or latency
    timer on a pty) carries the C loop as the TCP socket does."""
    sim = Simulator(ids=[1, 2], tcp=False, state_dir=str(tmp_path / "state")).start()
    try:
        done = _run(["sb_loop_bench", sim.url, str(tmp_path / "state" / "bus.clock"), "115200", "2", "20"])
    finally:
        finish(sim, [1, 2])
    assert done.returncode == 0, done.stdout + done.stderr
    words = dict(zip(*[iter(done.stdout.split())] * 2))
    assert words["cycles"] == "20" and int(words["missed"]) <= 2, done.stdout


USER_PROGRAM = r"""
#include <stdio.h>
#include "servobus/servobus_posix.h"
int main(int argc, char **argv) {
    sb_posix link;
    sb_bus bus;
    (void)argc;
    if (sb_tcp_open(&link, "127.0.0.1", (unsigned)atoi(argv[1])) != 0) return 2;
    sb_bus_init(&bus, sb_posix_transport(&link), 115200);
    sb_read_multi_turn_angle_request r = {1};
    sb_read_multi_turn_angle_answer a;
    sb_error e = sb_call_read_multi_turn_angle(&bus, &r, &a);
    if (e.status != SB_OK) { char w[160]; sb_error_text(&e, w, sizeof w); puts(w); return 1; }
    printf("servo %d at %ld\n", a.id, (long)a.angle);
    return 0;
}
"""


def test_a_users_program_builds_as_documented(sim3, tmp_path):
    """docs/c-library.md's command for a program of one's own: the
    library's sources beside it, no sanitizers needed."""
    (tmp_path / "my_program.c").write_text("#include <stdlib.h>\n" + USER_PROGRAM)
    build = subprocess.run(["bash", "-c", "gcc -std=c99 -Itools/servobus/include -Ibuild/host/generated_servobus "
                            f"{tmp_path}/my_program.c tools/servobus/src/sb_*.c "
                            f"build/host/generated_servobus/servobus/sb_*.c -o {tmp_path}/my_program"],
                           cwd=REPO, capture_output=True, text=True, timeout=120)
    assert build.returncode == 0, build.stderr
    assert "gcc -std=c99 -Itools/servobus/include -Ibuild/host/generated_servobus my_program.c" in \
        (REPO / "docs" / "c-library.md").read_text()  # the command the docs give, as built here
    done = subprocess.run([str(tmp_path / "my_program"), sim3.url.rsplit(":", 1)[1]], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.startswith("servo 1 at "), done.stdout + done.stderr


def test_a_silent_servo_costs_the_c_loop_a_slot_not_a_time_out(tmp_path):
    """An unplugged servo held every cycle of the C
    loop ~60 ms (a fixed 50 ms + 4 ms a servo). Now its answer is waited
    for as long as the wire takes (its bytes, the servos' turnaround, the
    margin, and a middle servo's 3 ms silence before the next takes its
    turn). Judged on a paced simulator's clock: a mean cycle under 20 ms."""
    for silent in ("2", "3"):  # one in the middle, the last
        words = _paced_loop(tmp_path, [1, 2, 3], 20, unplugged=silent)
        assert words["cycles"] == "20" and words["missed"] == "20", words
        assert float(words["seconds"]) / 20 < 0.020, words
