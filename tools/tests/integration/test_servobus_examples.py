"""servobus's host examples (tools/servobus/examples, docs/c-library.md)
against servo_sim: the ros2_control-style read()/write() cycle in C++, and
the C robot loop of scripts/c_loop_bench.sh. Both wait on the simulator's
clock (its file, state_dir/bus.clock): a loaded PC slows them, it does not
fail them. The simulator follows the wall clock (REAL_TIME): the examples
pace themselves on it."""
import subprocess
from pathlib import Path

from servoctl.servo import Servo
from servoctl.sim import Simulator

from ..launchers import REPO
from .conftest import finish

REAL_TIME = True
EXAMPLES = REPO / "build" / "host" / "tools" / "servobus"


def _run(args, timeout=120):
    """An example, stopped whatever happens (subprocess.run kills it on a timeout)."""
    return subprocess.run([str(EXAMPLES / args[0]), *args[1:]], capture_output=True, text=True, timeout=timeout)


def _where(sim):
    return sim.url.removeprefix("socket://"), str(Path(sim.state_dir) / "bus.clock")


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


def test_the_cycle_refuses_an_id_it_cannot_address_and_an_unknown_option():
    """No servo is opened: the arguments are refused first, naming what is wrong."""
    bad_id = _run(["sb_ros2_cycle", "127.0.0.1:1", "--ids", "1,300"])
    assert bad_id.returncode == 2 and "'300' is not a servo ID (0-253)" in bad_id.stderr, bad_id.stderr
    unknown = _run(["sb_ros2_cycle", "127.0.0.1:1", "--idz", "1"])
    assert unknown.returncode == 2 and "usage:" in unknown.stderr, unknown.stderr


def test_the_c_robot_loop_reads_every_state(sim3):
    address, clock = _where(sim3)
    done = _run(["sb_loop_bench", address, clock, "115200", "3", "40"])
    assert done.returncode == 0, done.stdout + done.stderr
    words = dict(zip(*[iter(done.stdout.split())] * 2))
    # A state missed only where a loaded PC stalls the host past a round's time-out.
    assert words["cycles"] == "40" and int(words["missed"]) <= 3, done.stdout
    # Its rate against the wire's limit is the benchmark's (docs/c-library.md);
    # here only that a cycle is never shorter than its bytes on the wire.
    assert 0.0 < float(words["ratio"]) <= 1.0, done.stdout


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
                            f"build/host/generated_servobus/servobus/sb_schema.c -o {tmp_path}/my_program"],
                           cwd=REPO, capture_output=True, text=True, timeout=120)
    assert build.returncode == 0, build.stderr
    assert "gcc -std=c99 -Itools/servobus/include -Ibuild/host/generated_servobus my_program.c" in \
        (REPO / "docs" / "c-library.md").read_text()  # the command the docs give, as built here
    done = subprocess.run([str(tmp_path / "my_program"), sim3.url.rsplit(":", 1)[1]], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.startswith("servo 1 at "), done.stdout + done.stderr


def test_a_silent_servo_costs_the_c_loop_a_slot_not_a_time_out(sim3):
    """An unplugged servo held every cycle of the C
    loop ~60 ms (a fixed 50 ms + 4 ms a servo). Now its answer is waited
    for as long as the wire takes (its bytes, the servos' turnaround, the
    margin, and a middle servo's 3 ms silence before the next takes its
    turn). Judged on the simulator's clock: a mean cycle under 20 ms."""
    address, clock = _where(sim3)
    for silent in ("2", "3"):  # one in the middle, the last
        assert sim3.control(f"unplug 1 {silent}").strip() == "ok"
        done = _run(["sb_loop_bench", address, clock, "115200", "3", "20"])
        assert sim3.control(f"unplug 0 {silent}").strip() == "ok"
        assert done.returncode == 0, done.stdout + done.stderr
        words = dict(zip(*[iter(done.stdout.split())] * 2))
        assert words["cycles"] == "20" and int(words["missed"]) >= 20, done.stdout
        assert float(words["seconds"]) / 20 < 0.020, done.stdout
