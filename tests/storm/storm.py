"""A long mixed storm against the simulator (three servos on one bus, the
ASan + UBSan build of servo_sim), with a summary at the end.

One host, as on a real bus, mixes without pause:
  - requests that must be answered (ping, ReadData, ReadMotion, Monitor);
  - moves that preempt each other (servo 3, control response off);
  - moves answered when finished (servos 1 and 2, control response on);
  - Sync Monitor rounds, some listing an absent servo;
  - config writes (stall power 38, soft-start time 50), each remembered,
    one at a time and in bursts of 10-40 that fill the store's pages (a
    change the servo cannot make durable is refused, and must not appear);
  - releases (StopOnControl, release) followed by quiet, so a servo with a
    full page erases its spare one (40 ms with the CPU stalled);
  - garbage at line rate, bytes that hold no frame header (0x12, 0x05);
  - faults through the control port: supply sags and surges, loads beyond
    the stall torque, hard stops, heat;
  - power cuts: servo_sim killed with SIGKILL at random, restarted on the
    same flash files, every servo's config read back and checked.

Summary: frames lost (an answer due and not received, or received garbled,
and not counted by the servo in ReadStore's answers dropped or bytes lost),
collisions, control ticks dropped, configs corrupted (a value after a cut
that was never written), changes lost (acknowledged and gone after a cut:
an acknowledged change is durable), sanitizer findings. All must be 0.
An answer the servo did not send because the request arrived during its
erase is counted apart (answers missed, reported): the host learns of it
from ReadStore, as docs/decisions.md tells it to. So is an answer the host
talked over: its request started on the wire within about a byte time of a
finished move's answer, too late for the servo to hear it first, and the
two garbled each other (docs/decisions.md, "The host"; the simulator's
garbled bytes beyond its collisions). The request is lost with the answer,
and with it any frames the servos' framers took for its content; what came
of the answer runs into the next frame, which the host finds garbled.

Every wait for an answer is in simulated time (the control port's clock):
on a loaded PC the simulator falls behind the host, and a late answer is
not a lost one. The storm's length and its pacing are the host's.

    python tests/storm/storm.py --minutes 30 --seed 1 --out build/storm-1
"""
import argparse
import json
import random
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

from servoctl import protocol as p  # noqa: E402
from servoctl.protocol import checksum, request_frame  # noqa: E402
from servoctl.sim import Simulator, control_command  # noqa: E402

try:
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
except ImportError:  # the storm runs without rich, only less pretty
    Progress = None

SIM = ROOT / "build/host/firmware/boards/host_sim/servo_sim"
IDS = (1, 2, 3)
ANSWERING = (1, 2)  # control response on
BYTE_S = 10 / 115200
CONFIG_ITEMS = (38, 50)
RELEASE = 0x10  # StopOnControl: stop and release
NO_HEADER = bytes(b for b in range(256) if b not in (0x12, 0x05))


class Sim(Simulator):
    """servo_sim on a TCP port, its stderr in a log file; its clock and
    control port are servoctl's Simulator's (the clock file it maps, the
    control port else)."""

    def __init__(self, binary: Path, state: Path, log: Path):
        super().__init__(ids=IDS, state_dir=str(state))
        self.binary, self.state, self.log = binary, state, log

    def start(self):
        self.errors = open(self.log, "a")
        cmd = [str(self.binary), "--state", str(self.state), "--tcp", "0",
               *sum((["--id", str(i)] for i in IDS), [])]
        self.process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.errors, text=True)
        self._until_ready(cmd)
        host, port = self.url.replace("socket://", "").split(":")
        self.sock = socket.create_connection((host, int(port)))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sock.settimeout(0.005)
        return self

    def command(self, line: str) -> str:
        return control_command(self.control_port, line, timeout=5)

    def state_of(self, servo_id: int) -> dict:
        out = {}
        for pair in self.command(f"state {servo_id}").split():
            key, _, value = pair.partition("=")
            out[key] = value
        return out

    def _end(self, sig):
        """Closes the bus, sends sig, and lets Simulator.stop close the
        clock and reap the process."""
        self.sock.close()
        self.process.send_signal(sig)
        self.process.wait(timeout=10)
        super().stop()
        self.errors.close()

    def kill(self):
        self._end(signal.SIGKILL)

    def stop(self):
        self._end(signal.SIGTERM)


class Host:
    """The one master on the bus: every frame that comes back is parsed; a
    finished move's answer may come at any time."""

    def __init__(self, sim: Sim, stats: dict):
        self.sim, self.stats = sim, stats
        self.buffer = b""
        self.finished = {i: 0 for i in ANSWERING}
        self.counted = {}  # servo -> answers dropped + bytes lost, as last read
        self.talked_seen = {}  # what for -> the simulator's talked_over, as last read

    def store_counts(self, servo_id: int):
        """What the servo says flash work cost the bus (ReadStore): answers
        it did not send plus bytes it lost; None if it does not answer."""
        self.send(request_frame(p.READ_STORE, bytes([servo_id])))
        got = self.listen(0.25, lambda c, body: c == p.READ_STORE and body[:1] == bytes([servo_id]))
        if got is None or len(got[1]) != 34:
            return None
        return sum(struct.unpack("<II", got[1][26:34]))

    def page_erases(self, servo_id: int) -> int:
        """The servo's store pages erased in its life (ReadStore)."""
        self.send(request_frame(p.READ_STORE, bytes([servo_id])))
        got = self.listen(1.0, lambda c, body: c == p.READ_STORE and body[:1] == bytes([servo_id]))
        return struct.unpack("<I", got[1][6:10])[0] if got is not None and len(got[1]) == 34 else 0

    def baseline(self, ids=IDS):
        for i in ids:
            count = self.store_counts(i)
            if count is not None:
                self.counted[i] = count

    def talked_over_since(self, what: str) -> bool:
        """Whether the host has talked over an answer since this was last
        asked for `what` (a missing answer, a garbled frame)."""
        talked, before = talked_over(self.sim.state_of(1)), self.talked_seen.get(what, 0)
        self.talked_seen[what] = talked
        return talked > before

    def missed(self, servo_id: int, what: str) -> bool:
        """An answer did not come. Reported if the servo's own counters
        rose since they were last read, talked over if the host garbled an
        answer meanwhile, otherwise a lost frame."""
        if self.talked_over_since("missing"):
            self.stats["answers_talked_over"] += 1
            return True
        count = self.store_counts(servo_id)
        reported = count is not None and count > self.counted.get(servo_id, count)
        if count is not None:
            self.counted[servo_id] = count
        if reported:
            self.stats["answers_missed_reported"] += 1
        else:
            self.stats["frames_lost"] += 1
            self.stats["lost_examples"].append(what)
        return reported

    def send(self, data: bytes):
        self.sim.sock.sendall(data)

    def garbled(self):
        """A frame failed its checksum. The host's own doing if it has talked
        over an answer since the last such frame: the answer's first bytes
        came, the rest was lost under the request, and the next frame ran
        into them."""
        if self.talked_over_since("garbled"):
            self.stats["garbled_talked_over"] += 1
        else:
            self.stats["garbled"] += 1

    def _frames(self):
        while True:
            start = self.buffer.find(p.RESPONSE_HEADER)
            if start < 0:
                keep = 1 if self.buffer.endswith(p.RESPONSE_HEADER[:1]) else 0
                self.stats["stray_bytes"] += len(self.buffer) - keep
                self.buffer = self.buffer[len(self.buffer) - keep:]
                return
            self.stats["stray_bytes"] += start
            self.buffer = self.buffer[start:]
            if len(self.buffer) < 5 or len(self.buffer) < 4 + self.buffer[3] + 1:
                return
            end = 4 + self.buffer[3] + 1
            frame, self.buffer = self.buffer[:end], self.buffer[end:]
            if checksum(frame[:-1]) != frame[-1]:
                self.garbled()
                continue
            yield frame[2], frame[4:-1]

    def listen(self, seconds: float, want=None):
        """Reads for up to `seconds` of simulated time; returns the first
        frame `want` accepts, counting finished-move answers on the way."""
        deadline = self.sim.clock_s() + seconds
        while True:
            for code, content in self._frames():
                if code in (p.ANGLE, p.MULTI_TURN_BY_INTERVAL) and content[:1] and content[0] in ANSWERING \
                        and len(content) == 2:
                    self.finished[content[0]] += 1
                    continue
                if want is not None and want(code, content):
                    return code, content
            if self.sim.clock_s() > deadline:
                return None
            try:
                data = self.sim.sock.recv(4096)
                if not data:
                    raise ConnectionError("servo_sim closed the bus")
                self.buffer += data
            except socket.timeout:
                pass

    def request(self, code: int, content: bytes, answers: bool = True, timeout: float = 0.25):
        self.send(request_frame(code, content))
        self.stats["requests"] += 1
        if not answers:
            return None
        wanted = lambda c, body: c == code and body[:1] == content[:1]  # noqa: E731
        # A slow host is not a lost frame: a second, longer look first.
        got = self.listen(timeout, wanted) or self.listen(1.0, wanted)
        if got is None:
            self.missed(content[0], f"packet {code} to {content[0]}")
        return got


def fault(sim: Sim, rng: random.Random, stats: dict):
    """Something physical happens to servo 3 (its own moves are not
    answered, so a refused move loses nothing)."""
    kind = rng.choice(["sag", "surge", "load", "stop", "heat", "clear"])
    cmd = {
        "sag": f"supply {rng.choice([3000, 4200, 5500])} 3",
        "surge": f"supply {rng.choice([8600, 9500])} 3",
        "load": f"load {rng.choice([-5.0, -2.0, 1.0, 4.0])} 3",
        "stop": f"stop {rng.uniform(-60, 60):.1f} 3",
        "heat": f"soak {rng.choice([60, 90, 110])} 3",
    }.get(kind)
    if kind == "clear":
        for line in ("supply 7400 3", "load 0 3", "stop off 3", "soak 25 3"):
            sim.command(line)
    else:
        sim.command(cmd)
    stats["faults"] += 1


def read_item(host: Host, servo_id: int, item: int):
    got = host.request(p.READ_DATA, bytes([servo_id, item]))
    if got is None or len(got[1]) != 4:
        return None
    return struct.unpack("<H", got[1][2:4])[0]


def talked_over(bus: dict) -> int:
    """Bytes a servo sent while the host's were on the wire, from `state`:
    the host's bytes wait for a quiet wire, so every garbled byte that is
    not a collision (a servo's over another's) is one of these: an answer
    and a request the host put on the wire within about a byte time of each
    other, before the servo could hear the request or the host the answer."""
    return int(bus["garbled"]) - int(bus["collisions"])


def count_finished(stats: dict, expected: dict, heard: dict, bus: dict, log):
    """At the end of a servo_sim's life (a cut or the storm's end), once the
    line has been left quiet for the answers: expected and heard, servo ->
    finished-move answers owed and received since servo_sim started; bus,
    its `state`. Answers missing where the host talked over an answer are
    the host's (which moves its garbled request took along cannot be told),
    elsewhere they are lost."""
    missing = {i: expected[i] - heard[i] for i in expected if expected[i] > heard[i]}
    if not missing:
        return
    if talked_over(bus) > 0:
        stats["finished_talked_over"] += sum(missing.values())
        log(f"finished answers missing {missing}, the host talked over answers "
            f"({talked_over(bus)} bytes garbled)")
    else:
        stats["finished_lost"] += sum(missing.values())
        log(f"finished answers lost {missing} (owed {expected}, heard {heard})")


def check_configs(host: Host, history: dict, stats: dict, log):
    """history: (servo, item) -> [(value, acknowledged)], oldest first; a
    write whose answer the servo did not send may or may not have been
    carried out. After a cut the item holds the last acknowledged value or
    a later unanswered one."""
    for (servo_id, item), writes in history.items():
        value = read_item(host, servo_id, item)
        if value is None:
            continue  # counted as a lost frame
        last_acked = max(n for n, (_, acked) in enumerate(writes) if acked)
        allowed = [v for v, _ in writes[last_acked:]]
        if value not in (v for v, _ in writes):
            stats["configs_corrupted"] += 1
            log(f"servo {servo_id} item {item}: {value} after the cut, never written")
        elif value not in allowed:
            stats["changes_lost"] += 1
            log(f"servo {servo_id} item {item}: {value} after the cut, "
                f"{writes[last_acked][0]} was acknowledged")
        # What survived is the history from here on.
        history[(servo_id, item)] = [(value, True)]


def write_config(host: Host, history: dict, stats: dict, servo_id: int, item: int, value: int):
    got = host.request(p.WRITE_DATA, bytes([servo_id, item]) + struct.pack("<H", value))
    if got is None:
        history[(servo_id, item)].append((value, False))
    elif got[1][2:3] == b"\x01":
        history[(servo_id, item)].append((value, True))
        stats["config_writes"] += 1
    else:
        stats["writes_refused"] += 1


def run(minutes: float, out: Path, seed: int):
    out.mkdir(parents=True, exist_ok=True)
    state = out / "state"
    shutil.rmtree(state, ignore_errors=True)
    # Its own copy: a rebuild during the storm must not change the servos.
    sim_binary = out / "servo_sim"
    shutil.copy2(SIM, sim_binary)
    sanitizer_log = out / "servo_sim.stderr"
    sanitizer_log.write_text("")
    rng = random.Random(seed)
    stats = {k: 0 for k in ("requests", "frames_lost", "garbled", "stray_bytes", "collisions",
                            "ticks_dropped", "configs_corrupted", "changes_lost", "power_cuts",
                            "moves", "answered_moves", "finished_answers", "finished_lost",
                            "sync_rounds", "config_writes", "garbage_bytes", "faults",
                            "configs_checked", "writes_refused", "write_bursts", "releases",
                            "answers_missed_reported", "answers_talked_over", "finished_talked_over",
                            "garbled_talked_over")}
    stats["lost_examples"] = []
    events = open(out / "events.log", "w")

    def log(text):
        events.write(f"{time.strftime('%H:%M:%S')} {text}\n")
        events.flush()

    sim = Sim(sim_binary, state, sanitizer_log)
    sim.start()
    host = Host(sim, stats)
    history = {}
    for i in IDS:
        host.request(p.WRITE_DATA, bytes([i, 49, 0]))  # soft start off
        host.request(p.WRITE_DATA, bytes([i, 33, 1 if i in ANSWERING else 0]))
        for item in CONFIG_ITEMS:
            history[(i, item)] = [(read_item(host, i, item), True)]
    host.baseline()
    expected = {i: 0 for i in ANSWERING}
    seen_base = dict(host.finished)
    end = time.monotonic() + minutes * 60
    next_cut = time.monotonic() + rng.uniform(20, 120)
    next_config = 0.0

    progress = None
    if Progress is not None:
        progress = Progress(TextColumn("storm"), BarColumn(), TextColumn("{task.fields[line]}"),
                            TimeRemainingColumn(), console=Console(stderr=True))
        progress.start()
        task = progress.add_task("storm", total=minutes * 60, line="")
    start = time.monotonic()

    def answers_heard():
        return {i: host.finished[i] - seen_base[i] for i in ANSWERING}

    def settle_answers():
        """Leave the line quiet until every finished move has answered
        (each goes out in its slot once the host pauses)."""
        deadline = sim.clock_s() + 3.0
        while sim.clock_s() < deadline:
            if all(host.finished[i] - seen_base[i] >= expected[i] for i in ANSWERING):
                return
            host.listen(0.05)

    while time.monotonic() < end:
        now = time.monotonic()
        if now >= next_cut:
            settle_answers()
            st = sim.state_of(1)
            count_finished(stats, expected, answers_heard(), st, log)
            stats["collisions"] += int(st["collisions"])
            stats["ticks_dropped"] += sum(int(sim.state_of(i)["dropped_ticks"]) for i in IDS)
            sim.kill()
            stats["power_cuts"] += 1
            log(f"power cut {stats['power_cuts']}")
            sim.start()
            host = Host(sim, stats)
            seen_base = dict(host.finished)
            expected = {i: 0 for i in ANSWERING}
            check_configs(host, history, stats, log)
            host.baseline()
            stats["configs_checked"] += len(history)
            next_cut = time.monotonic() + rng.uniform(20, 120)
            continue
        action = rng.choices(
            ["query", "preempt", "answered_move", "sync", "config", "burst", "release", "garbage",
             "fault", "listen"],
            weights=[30, 20, 8, 8, 5, 1, 3, 6, 3, 6])[0]
        if action == "query":
            i = rng.choice(IDS)
            kind = rng.choice([(p.PING, bytes([i])), (p.READ_DATA, bytes([i, rng.choice([1, 5, 33, 50])])),
                               (p.READ_MOTION, bytes([i])), (p.MONITOR, bytes([i])),
                               (p.READ_MULTI_TURN, bytes([i]))])
            host.request(*kind)
        elif action == "preempt":
            host.request(p.ANGLE_BY_INTERVAL, struct.pack("<BhHHHH", 3, rng.randint(-1800, 1800),
                                                          rng.randint(40, 600), 20, 20, 0), answers=False)
            stats["moves"] += 1
        elif action == "answered_move":
            i = rng.choice(ANSWERING)
            if expected[i] - (host.finished[i] - seen_base[i]) < 3:
                host.request(p.ANGLE, struct.pack("<BhHH", i, rng.randint(-900, 900), rng.randint(50, 300), 0),
                             answers=False)
                expected[i] += 1
                stats["answered_moves"] += 1
        elif action == "sync":
            order = rng.sample(IDS, 3) + ([9] if rng.random() < 0.3 else [])
            rng.shuffle(order)
            host.send(request_frame(p.SYNC, bytes([p.MONITOR, 1, len(order)] + order)))
            stats["sync_rounds"] += 1
            # One listen for the whole round: a servo that stays silent (its
            # request fell in an erase) must not make the host skip past
            # the answers that follow it.
            present = [s for s in order if s in IDS]
            heard = set()

            def round_done(c, body):
                if c == p.MONITOR and body[:1] and body[0] in present:
                    heard.add(body[0])
                return heard >= set(present)

            stats["requests"] += len(present)
            host.listen(0.3 + 0.004 * len(order), round_done)
            absent = [sid for sid in present if sid not in heard]
            if absent and host.talked_over_since("missing"):  # a garbled round loses all its answers
                stats["answers_talked_over"] += len(absent)
            else:
                for sid in absent:
                    host.missed(sid, f"sync monitor answer of {sid} in {order}")
        elif action == "config" and time.monotonic() >= next_config:
            next_config = time.monotonic() + rng.uniform(1.0, 3.0)
            write_config(host, history, stats, rng.choice(IDS), rng.choice(CONFIG_ITEMS),
                         rng.randint(100, 60000))
        elif action == "burst":
            # Enough changes to fill a page or two: past the erased space the
            # servo refuses, and a cut may follow at once.
            i = rng.choice(IDS)
            for _ in range(rng.randint(10, 40)):
                write_config(host, history, stats, i, rng.choice(CONFIG_ITEMS), rng.randint(100, 60000))
            stats["write_bursts"] += 1
            if rng.random() < 0.15:
                next_cut = time.monotonic()
        elif action == "release":
            # Released and left quiet, a servo whose page is full erases the
            # spare one. Not one whose finished move is still to answer.
            i = rng.choice([s for s in IDS if s not in ANSWERING or expected[s] == host.finished[s] - seen_base[s]])
            host.request(p.STOP_ON_CONTROL, struct.pack("<BBH", i, RELEASE, 0), answers=False)
            stats["releases"] += 1
            host.listen(rng.uniform(0.05, 0.3))
        elif action == "garbage":
            burst = bytes(rng.choice(NO_HEADER) for _ in range(rng.randint(16, 2048)))
            host.send(burst)
            stats["garbage_bytes"] += len(burst)
            host.listen(len(burst) * BYTE_S + 0.01)  # the line is busy meanwhile
            host.baseline()  # bytes lost to a stall in the garbage are no lost frame
        elif action == "fault":
            fault(sim, rng, stats)
        else:
            host.listen(rng.uniform(0.01, 0.2))
        if sum(expected[i] - (host.finished[i] - seen_base[i]) for i in ANSWERING) > 0 and rng.random() < 0.1:
            host.listen(0.2)  # a pause, as a host waiting for answers makes
        if progress is not None:
            progress.update(task, completed=time.monotonic() - start,
                            line=f"requests {stats['requests']} lost {stats['frames_lost']} "
                                 f"cuts {stats['power_cuts']}")
    settle_answers()
    st = sim.state_of(1)
    count_finished(stats, expected, answers_heard(), st, log)
    stats["collisions"] += int(st["collisions"])
    stats["ticks_dropped"] += sum(int(sim.state_of(i)["dropped_ticks"]) for i in IDS)
    stats["page_erases"] = sum(host.page_erases(i) for i in IDS)
    sim.stop()
    if progress is not None:
        progress.stop()
    text = sanitizer_log.read_text()
    stats["sanitizer_findings"] = len(re.findall(r"runtime error|AddressSanitizer|LeakSanitizer", text))
    stats["finished_answers"] = stats["answered_moves"] - stats["finished_lost"] - stats["finished_talked_over"]
    stats["minutes"] = minutes
    stats["seed"] = seed
    stats["lost_examples"] = stats["lost_examples"][:20]
    (out / "summary.json").write_text(json.dumps(stats, indent=2))
    must_be_zero = ("frames_lost", "garbled", "finished_lost", "collisions", "ticks_dropped",
                    "configs_corrupted", "changes_lost", "sanitizer_findings")

    lines = [f"storm: {minutes:g} min, seed {seed}, 3 servos at 115200 baud",
             f"  requests {stats['requests']}, sync rounds {stats['sync_rounds']}, moves {stats['moves']}"
             f" preempting, {stats['answered_moves']} answered moves, {stats['config_writes']} config writes,"
             f" {stats['garbage_bytes']} garbage bytes, {stats['faults']} faults, {stats['power_cuts']} power cuts"
             f" ({stats['configs_checked']} configs checked)",
             f"  {stats['write_bursts']} write bursts, {stats['writes_refused']} writes refused (not durable),"
             f" {stats['releases']} releases, {stats['page_erases']} page erases,"
             f" {stats['answers_missed_reported']} answers missed and reported in ReadStore",
             f"  talked over by the host (its request within a byte time of an answer):"
             f" {stats['answers_talked_over']} answers asked for, {stats['finished_talked_over']} finished answers,"
             f" {stats['garbled_talked_over']} frames garbled"]
    lines += [f"  {key.replace('_', ' ')}: {stats[key]}" for key in must_be_zero]
    summary = "\n".join(lines)
    (out / "summary.txt").write_text(summary + "\n")
    print(summary)
    return all(stats[k] == 0 for k in must_be_zero)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--out", type=Path, default=ROOT / "build/storm")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    if not SIM.exists():
        sys.exit(f"storm: {SIM} is missing; build it with: cmake --preset host && cmake --build --preset host")
    ok = run(args.minutes, args.out, args.seed)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
