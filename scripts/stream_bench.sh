#!/usr/bin/env bash
# Streamed setpoints against plain angle moves, and the robot loop at the
# wire's speed (docs/streaming.md, "Figures"):
#  1. one servo on the plant model (tests/unit/test_stream.c): a 0.5 Hz
#     +-60 deg sine sent at 50 Hz, streamed and as 20 ms angle moves: the RMS
#     error to the sine and the setpoint's peak acceleration;
#  2. the same path on 6 simulated servos (servo_sim, paced) at 1 Mbaud,
#     through servoctl: the RMS error of each servo's Sync Monitor state;
#     then streamed on the optimised simulator in real time, the host on
#     its own clock, on time and with the host-timing model (+-10 ms, one
#     frame in twenty a period late): the PC's own timing in the figure;
#  3. the robot loop (one SyncCommand of setpoints and one Sync Monitor a
#     cycle, servoctl.stream.RobotLoop) for 6 and 16 servos at 1 000 000 and
#     115 200 baud: its rate against the wire limit, the host behind the
#     simulated USB adapter (the default) and on the raw link (each byte as
#     it ends on the wire: servoctl against the wire alone; docs/simulator.md).
# Times are the simulator's clock. Not part of the test command (a minute).
#   bash scripts/stream_bench.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
cmake --preset host >/dev/null
cmake --build --preset host --target servo_sim test_stream >/dev/null
cmake --preset sim >/dev/null && cmake --build --preset sim >/dev/null  # the real-time rows' simulator
echo "1. one servo on the plant model (tests/unit/test_stream.c):"
build/host/tests/test_stream 2>/dev/null | sed -n 's/^# /   /p' | head -1
exec .venv/bin/python - <<'PY'
import math
import sys

sys.path.insert(0, "scripts")
from bench_sim import at_baud, cycle_gaps  # the simulated servos at a rate, a cycle's gaps
import os

from servoctl import protocol as p
from servoctl.group import sync_move, sync_monitor
from servoctl.host_timing import HostTiming
from servoctl.stream import RobotLoop, stream_file

PERIOD, SECONDS = 0.02, 4.0


def path(t):
    return 60.0 * math.cos(math.pi * t)  # 0.5 Hz, +-60 deg, from rest at its peak


def plain_moves(bus, ids, times):
    """The path as 20 ms MoveAngle records, one SyncCommand a period; each
    cycle's Sync Monitor against the path when it was taken."""
    answer_s = p.answer_frame_size(p.MONITOR) * 10 / bus.serial.baudrate
    start = bus.clock() + PERIOD
    errors = []
    for k, t in enumerate(times):
        bus.sleep(max(0.0, start + (k - 1) * PERIOD - bus.clock()))
        body = b"".join(p.encode_request(p.ANGLE, i, round(path(t) * 10), 20, 0) for i in ids)
        bus.send(p.SYNC, bytes([p.ANGLE, len(body) // len(ids), len(ids)]) + body)
        arrivals = {}
        states = sync_monitor(bus, ids, arrivals=arrivals)
        if k and states:  # when the states were taken (servoctl.stream.stream_file)
            at = min(arrivals[i] - (n + 1) * answer_s for n, i in enumerate(ids) if i in states) - start
            errors += [states[i].angle_decideg / 10 - path(at) for i in ids if i in states]
    return math.sqrt(sum(e * e for e in errors) / len(errors)), max(map(abs, errors))


ids = list(range(1, 7))
times = [k * PERIOD for k in range(int(SECONDS / PERIOD) + 1)]
print("2. 6 servos at 1 Mbaud, the same path through servoctl (Sync Monitor each period):")
for streamed in (True, False):
    with at_baud(ids, 1000000, paced=True) as sim, sim.bus(baud=1000000, timeout=0.1) as bus:
        sync_move(bus, {i: path(0) for i in ids}, 0.5, multi_turn=True)
        bus.sleep(0.7)
        if streamed:
            r = stream_file(bus, times, {i: [path(t) for t in times] for i in ids})
            rms, peak = max(r.rms_deg.values()), max(r.peak_deg.values())
        else:
            rms, peak = plain_moves(bus, ids, times)
    how = "streamed     " if streamed else "angle moves  "
    print(f"   {how} RMS error {rms:.2f} deg, peak {peak:.2f} deg (the worst servo)")
os.environ["SERVO_SIM"] = "build/sim/firmware/boards/host_sim/servo_sim"
for host in (None, HostTiming(0.010, 20)):
    with at_baud(ids, 1000000) as sim, p.Bus(sim.url, baud=1000000, timeout=0.1) as bus:  # the wall clock's
        sync_move(bus, {i: path(0) for i in ids}, 0.5, multi_turn=True)
        bus.sleep(0.7)
        r = stream_file(bus, times, {i: [path(t) for t in times] for i in ids}, host=host)
    how = "real time, +-10 ms, 1 in 20 late" if host else "real time, on time"
    print(f"   streamed, {how}: RMS error {max(r.rms_deg.values()):.2f} deg, "
          f"peak {max(r.peak_deg.values()):.2f} deg (the worst servo)")

print("3. the robot loop through servoctl's Python API (RobotLoop.cycle, 200 cycles):")
for count, baud, link in [(c, b, l) for l in ("usb", "raw") for c in (6, 16) for b in (1000000, 115200)]:
    if count == 6 and baud == 1000000:
        print(f"   host link {link}:")
    ids = list(range(1, count + 1))
    with at_baud(ids, baud, link) as sim, sim.bus(baud=baud, timeout=0.1) as bus:
        loop = RobotLoop(bus, ids, PERIOD, pace=False)  # as fast as the wire goes
        for k in range(200):
            loop.cycle({i: 10.0 * math.sin(k / 20) for i in ids})
        r = loop.rate()
        host, first, between = cycle_gaps(sim)
    print(f"   {count:2} servos at {baud:7} baud: {r.rate_hz:6.0f} Hz of the wire's {r.wire_limit_hz:6.0f} "
          f"({r.ratio:.2f}), {loop.missed} state(s) missed; a cycle's gaps on the wire (mean us): "
          f"host {host:.0f}, first answer {first:.0f}, between answers {between:.1f}")
PY
