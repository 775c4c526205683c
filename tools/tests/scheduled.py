"""Frames put on the simulated wire at simulated times, through the control
port's hostsend (servo_sim's and the virtual boards'). A test that times its
frames this way judges what the servo does with them, when it got them: a
host that a loaded PC runs late changes nothing (docs/testing.md, "Under
load"). Only frames that nothing answers are queued far ahead: the wire is
the host's until its last queued byte, and an answer would wait behind it
(and servo_sim calls the next servo's answer a collision)."""
import math
import socket
import time

from servoctl import protocol as p
from servoctl.checks import scaled
from servoctl.stream import Limits, Stream

LINE_BYTES = 100  # hostsend's most bytes a line
LEAD_S = 0.5      # from the schedule's making to its first frame, simulated
QUEUE_BYTES = 8192  # servo_sim's wire holds that many bytes queued (SIM_BUS_QUEUE)


def schedule(sim, frames) -> None:
    """frames, [(at_s, bytes)] on the simulator's clock, rising: all of
    them through one control connection, so the last is queued as soon as
    the first. Fails if the clock had passed the first frame's time by
    then (the frames would not be where the test put them)."""
    assert sum(len(data) for _, data in frames) <= QUEUE_BYTES, "more than the simulated wire queues"
    lines = [f"hostsend {at_s * 1000:.3f} {data[k:k + LINE_BYTES].hex()}\n"
             for at_s, data in frames for k in range(0, len(data), LINE_BYTES)]
    with socket.create_connection(("127.0.0.1", sim.control_port), timeout=30) as conn:
        conn.sendall("".join(lines).encode())
        conn.shutdown(socket.SHUT_WR)
        reply = b""
        while chunk := conn.recv(65536):
            reply += chunk
    assert reply.decode().split() == ["ok"] * len(lines), reply
    assert sim.clock_s() < frames[0][0], "the schedule was made after its first frame was due"


def followed(sim, times, angles: dict, baud: int = 115200) -> dict:
    """Streams a trajectory ({id: [degrees...]} at times, evenly spaced,
    the servos at rest at its first row) as servoctl stream does (each row
    stamped with its time and sent the servo's depth, 3/2 period, before
    it; velocities the central differences of the
    rows, 0 at both ends; one SyncCommand of setpoints a period), every
    frame put on the simulated wire at its time before the first is due
    (a setpoint is not answered: nothing else is on the wire meanwhile).
    Meanwhile the models' state (the control port's, each with its own
    simulated time) is read as often as the host can: each horn's angle is
    compared with the trajectory as the servo was given it, each row
    reached the depth after its setpoints' last byte arrived
    (docs/streaming.md). {id: (RMS, peak, samples)} in deg."""
    ids = list(angles)
    period = times[1] - times[0]
    stream = Stream(None, ids, period, limits={i: Limits() for i in ids})
    count = len(times)
    sent = {i: [scaled(a, 10, "degrees") for a in angles[i]] for i in ids}

    def velocity(i, k):
        return 0.0 if k in (0, count - 1) else (sent[i][k + 1] - sent[i][k - 1]) / (20 * period)

    row0_s = sim.clock_s() + LEAD_S
    frames = []
    for k in range(count):
        code, content = stream.frame_content({i: angles[i][k] for i in ids}, {i: velocity(i, k) for i in ids})
        stream.sent += 1
        frames.append((row0_s + (k - 1.5) * period, p.request_frame(code, content)))
    schedule(sim, frames)
    lag = len(frames[0][1]) * 10 / baud  # a row is reached the depth after its frame's last byte

    def reference(i, t):
        x = min(max((t - lag - row0_s) / period, 0.0), count - 1.0)
        k = min(int(x), count - 2)
        return angles[i][k] + (angles[i][k + 1] - angles[i][k]) * (x - k)

    errors = {i: [] for i in ids}
    end_s = row0_s + (count - 1) * period + lag
    while True:
        states = [dict(w.split("=", 1) for w in line.split()) for line in sim.control("state").splitlines()
                  if line.startswith("id=")]
        t = float(states[0]["sim_ms"]) / 1000
        if t > end_s:
            break
        if t >= row0_s:
            for st in states:
                i = int(st["id"])
                errors[i].append(float(st["angle"]) - reference(i, t))
        time.sleep(0.002)
    return {i: (math.sqrt(sum(e * e for e in v) / len(v)), max(map(abs, v)), len(v)) for i, v in errors.items()}
