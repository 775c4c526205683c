#!/usr/bin/env bash
# The robot loop (one SyncCommand of setpoints and one Sync Monitor a
# cycle, as fast as the wire goes) in C (servobus's sb_loop_cycle,
# tools/servobus/examples/loop_bench.c, built -O2 without sanitizers) and
# through servoctl's Python API (servoctl.stream.RobotLoop) beside it, for 6
# and 16 servos at 1 000 000 and 115 200 baud on servo_sim: cycles a
# second, the wire's limit (servoctl's loop_rate.wire_limit_hz, sb_wire_limit_hz),
# their ratio, and the mean gaps of a cycle on the simulator's wire log:
# the last answer's end to the host's next burst ("host"), the burst's end
# to the first answer, and between answers. "servos' bound" is the ratio a
# host that answered in no time would reach: the wire and the servos' gaps
# alone. Times are the simulator's clock; the host reads each byte as it
# ends on the wire (--host-link raw; HOST_LINK=usb for the USB adapter's
# frames). Run as root, the benchmark and the simulators it starts take the
# real-time scheduler (SCHED_FIFO): a loaded PC's other processes then do
# not put their time into the hosts' gaps; otherwise they run as started,
# and the table says so. Not part of the test command (about a minute;
# docs/c-library.md).
#   bash scripts/c_loop_bench.sh [CYCLES]      (default 200)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
cmake --preset host >/dev/null
cmake --build --preset host --target servo_sim servobus >/dev/null
out=build/c-loop-bench
mkdir -p "$out"
gcc -std=c99 -O2 -Wall -Wextra -Werror -Itools/servobus/include -Itools/servobus -Ibuild/host/generated_servobus \
  tools/servobus/src/sb_*.c build/host/generated_servobus/servobus/sb_*.c \
  tools/servobus/examples/loop_bench.c tools/servobus/examples/sb_sim_clock.c -lm -o "$out/sb_loop_bench"
CYCLES=${1:-200} HOST_LINK=${HOST_LINK:-raw} BENCH="$out/sb_loop_bench" exec .venv/bin/python - <<'PY'
import math
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, "scripts")
from bench_sim import at_baud, cycle_gaps  # the simulated servos at a rate, a cycle's gaps
from servoctl.loop_rate import cycle_bytes
from servoctl.stream import RobotLoop

CYCLES, LINK, BENCH = int(os.environ["CYCLES"]), os.environ["HOST_LINK"], os.environ["BENCH"]
try:  # inherited by the simulators and the C loop this process starts
    os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(20))
    PRIORITY = "real-time (SCHED_FIFO)"
except OSError:
    PRIORITY = "as started (not root: no real-time scheduling)"


def c_loop(sim, count, baud):
    clock = str(Path(sim.state_dir) / "bus.clock")
    done = subprocess.run([BENCH, sim.url.removeprefix("socket://"), clock, str(baud), str(count), str(CYCLES)],
                          capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise SystemExit(f"sb_loop_bench: {done.stderr.strip()}")
    words = dict(zip(*[iter(done.stdout.split())] * 2))
    return float(words["rate"]), float(words["wire"]), int(words["missed"])


def python_loop(sim, count, baud):
    ids = list(range(1, count + 1))
    with sim.bus(baud=baud, timeout=0.1) as bus:
        loop = RobotLoop(bus, ids, 0.02, pace=False)  # as fast as the wire goes
        for k in range(CYCLES):
            loop.cycle({i: 10.0 * math.sin(k / 20) for i in ids})
        r = loop.rate()
    return r.rate_hz, r.wire_limit_hz, loop.missed


print(f"the robot loop, {CYCLES} cycles, host link {LINK}, priority {PRIORITY} (times: the simulator's clock)")
print("| servos | baud | loop | cycles/s | wire limit | ratio | host | first answer | between answers | servos' bound |")
print("|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|")
for count in (6, 16):
    for baud in (1000000, 115200):
        for name, run in (("C (servobus)", c_loop), ("Python (servoctl)", python_loop)):
            with at_baud(list(range(1, count + 1)), baud, LINK) as sim:
                rate, wire, missed = run(sim, count, baud)
                host, first, between = cycle_gaps(sim)
            wire_us = cycle_bytes(list(range(1, count + 1))) * 10 * 1e6 / baud
            bound = wire_us / (wire_us + first + (count - 1) * between)
            note = f" ({missed} missed)" if missed else ""
            print(f"| {count} | {baud} | {name}{note} | {rate:.0f} | {wire:.0f} | **{rate / wire:.3f}** | "
                  f"{host:.0f} us | {first:.0f} us | {between:.1f} us | {bound:.3f} |")
PY
