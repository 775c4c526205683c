"""Runs virtual boards on one bus with a control port, as servo_sim does:

    python -m vboard --board stm32f103|FOLDER [--build DIR] [--id N ...] [--tcp PORT | --link PATH]
                     [--state DIR] [--supply MV] [--ambient DEGC] [--plant FILE]
                     [--host-link usb|ftdi[:MS]|raw] [--clock wall|paced]

prints `vboard: bus URL`, `vboard: control 127.0.0.1:PORT`, `vboard: servos
...` and `vboard: ready`, so servoctl and the tests drive it as they drive
servo_sim. The control port takes servo_sim's commands (help lists them),
and the virtual boards' own: cutprogram, cutflash, peek, and the servo's faults,
inject ID bus|undef|stack|hang and brownout ID [MS] (inject.py).

A board is a shipped one by name, or any board folder by its path (a
board of an emulated part, its instances and pins from its board.h:
wiring.py), its images from the build tree --build names (default: the
checkout's build of its part's preset).

Simulated time follows the wall clock when the boards keep up, and falls
behind it when they do not (the emulated CPUs are slower than silicon on
most PCs); the bus's byte timing is simulated time either way. The clock
is published in the state folder's bus.clock (`vboard: clock PATH`, as
servo_sim's), where a host that waits on it (the tests) may tell the boards
to run ahead as fast as the emulator goes (clock_file.py). With --clock
paced the boards never follow the wall clock: they run only while such a
host waits, so what it does between its waits takes no simulated time
(servo_sim's --clock paced; a test's host-timing model is then exact)."""
import argparse
import os
import select
import signal
import socket
import sys
import tempfile
import time

import servo_schema as schema

from pathlib import Path

from servo_image import board_facts

from .board import PARTS, Board, images, part_of
from .bus import Bus
from .clock_file import ClockFile
from .usb import Adapter

MAX_SLICE_S = 1e-3  # longest the CPUs run between two looks at the host and the models
PACED_POLL_S = 2e-4  # how often paced boards standing still look at the host (servo_sim's)
# The control port's commands (protocol/control_port.toml, as servo_sim's): what
# help answers, and the range of each one's number.
CONTROLS = {c.name: c for c in schema.load().controls_of("vboard")}
HELP = schema.load().help_line("vboard")


class Runner:
    def __init__(self, args):
        self.bus = Bus(args.host_link)
        self.state_dir = args.state or tempfile.mkdtemp(prefix="vboard-")
        os.makedirs(self.state_dir, exist_ok=True)
        supply_v = None if args.supply is None else args.supply / 1000.0
        self.boards = [Board(args.board, i, self.bus, self.state_dir, supply_v, args.ambient,
                             app_image=args.app, unit=args.id[:k].count(i), plant=args.plant,
                             build=getattr(args, "build", None))
                       for k, i in enumerate(args.id)]
        self.url = self.bus.serve_tcp(args.tcp) if args.tcp is not None else self.bus.serve_pty(args.link)
        self.control = socket.socket()
        self.control.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.control.bind(("127.0.0.1", 0))
        self.control.listen(8)
        self.control.setblocking(False)
        self.clients = {}
        self.now_s = 0.0
        self.wall0 = time.monotonic()
        self.most_behind_s = 0.0
        self.clock = ClockFile(self.state_dir)
        self.paced = args.clock == "paced"
        self.bus.paced = self.paced
        self.stop_requested = False

    # ---- control port -----------------------------------------------------
    def command(self, line: str) -> str:
        words = line.split()
        if not words:
            return ""
        cmd = words[0]
        if cmd == "clock":
            return f"sim_ms={self.now_s * 1000:.3f} behind_ms={(self._wall() - self.now_s) * 1000:.1f}"
        if cmd == "help":
            return HELP
        if cmd == "hostsend":
            return self.host_send(words)
        if cmd == "peek":  # peek ADDR N ID: a board's memory, in hex (for debugging)
            try:
                address, n, wanted = int(words[1], 0), int(words[2], 0), int(words[3])
                board = next(b for b in self.boards if b.bus_id() == wanted)
                return bytes(board.core.uc.mem_read(address, min(n, 256))).hex()
            except (IndexError, ValueError, StopIteration) as e:
                return f"error: peek takes ADDR N ID ({e})"
        if cmd in ("inject", "brownout") and cmd in CONTROLS:
            return self.inject(words)
        control = CONTROLS.get(cmd)
        if control is None:
            return "error: unknown command (try help)"
        takes_value = control.value is not None
        id_word = 2 if takes_value else 1
        boards = self.boards
        if len(words) > id_word:  # the ID a board holds now, not the one it started with
            try:
                wanted = int(words[id_word])
            except ValueError:
                wanted = None
            boards = [b for b in self.boards if b.bus_id() == wanted]
            if not boards:
                return "error: no servo holds that ID"
        value = 0.0
        if takes_value:
            if len(words) < 2:
                return "error: missing value"
            if words[1] == "off" and not control.off:
                return "error: only stop takes off"
            if words[1] != "off":
                try:
                    value = float(words[1])
                except ValueError:
                    return "error: the value must be a number"
                lo, hi, unit = control.value
                if not lo <= value <= hi:
                    return f"error: {cmd} takes {lo:g} to {hi:g} {unit}, not {words[1]}"
        if cmd == "hostbaud":
            self.bus.host_baud = int(value)
            return "ok"
        out = []
        for b in boards:
            if cmd == "supply":
                b.motor.set("supply_v", value / 1000.0)
            elif cmd == "load":
                b.motor.set("load_nm", value)
            elif cmd == "payload":
                b.motor.set("payload_gcm2", value)
            elif cmd == "ambient":
                b.motor.set("ambient_c", value)
            elif cmd == "soak":
                b.motor.set("soak_c", value)
            elif cmd == "stop":
                b.motor.set("stop_deg", 1e9 if words[1] == "off" else value)
            elif cmd == "failerase":
                b.flash.fail_erases = int(value)
            elif cmd == "failprogram":
                b.flash.fail_programs = int(value)
            elif cmd == "cutprogram":
                b.flash.cut_after_programs = int(value)
            elif cmd == "cutflash":
                b.flash.cut_after_ops = int(value)
            elif cmd == "powercycle":
                b.power_cycle()
            elif cmd == "state":
                s = b.state()
                s.update(collisions=self.bus.collisions, garbled=self.bus.garbled, host_baud=self.bus.host_baud,
                         most_behind_ms=round(self.most_behind_s * 1000, 1))
                out.append(" ".join(f"{k}={v}" for k, v in s.items()))
            else:
                return "error: unknown command (try help)"
        return "\n".join(out) if out else "ok"

    def inject(self, words) -> str:
        """inject ID bus|undef|stack|hang (inject.py); brownout ID [MS]:
        VDD below the power-down level for MS ms (5), RAM kept."""
        usage = ("error: inject takes ID and bus, undef, stack or hang" if words[0] == "inject"
                 else "error: brownout takes ID and a dip of 0.01 to 1000 ms (5 if none)")
        try:
            wanted = int(words[1])
            extra = words[2:]
        except (IndexError, ValueError):
            return usage
        board = next((b for b in self.boards if b.bus_id() == wanted), None)
        if board is None:
            return "error: no servo holds that ID"
        if words[0] == "inject":
            return board.injector.inject(extra[0]) if len(extra) == 1 else usage
        try:
            dip_ms = float(extra[0]) if extra else 5.0
        except ValueError:
            return usage
        if len(extra) > 1 or not 0.01 <= dip_ms <= 1000:
            return usage
        board.brownout(dip_ms / 1000)
        return "ok"

    def host_send(self, words) -> str:
        """hostsend MS HEX: the host's bytes on the wire from simulated time
        MS on (or at once, if that has passed), paced at the host's rate, as
        servo_sim's: a test times a frame into a window of milliseconds."""
        usage = "error: hostsend takes a time in ms and 1 to 100 bytes in hex"
        if len(words) != 3:
            return usage
        try:
            at_s = float(words[1]) / 1000.0
            data = bytes.fromhex(words[2])
        except ValueError:
            return usage
        if not 0 < len(data) <= 100 or not at_s >= 0:
            return usage
        for byte in data:
            self.bus.queue_host(byte, max(at_s, self.now_s))
        return "ok"

    def serve_control(self, readable) -> None:
        if self.control in readable:
            try:
                conn, _ = self.control.accept()
                conn.setblocking(False)
                self.clients[conn] = b""
            except BlockingIOError:
                pass
        for conn in [c for c in self.clients if c in readable]:
            try:
                data = conn.recv(4096)
            except BlockingIOError:
                continue
            except OSError:
                data = b""
            if not data:
                conn.close()
                del self.clients[conn]
                continue
            self.clients[conn] += data
            while b"\n" in self.clients[conn]:
                line, self.clients[conn] = self.clients[conn].split(b"\n", 1)
                reply = self.command(line.decode(errors="replace"))
                try:
                    conn.sendall((reply + "\n").encode())
                except OSError:
                    pass

    # ---- the loop ---------------------------------------------------------
    def _wall(self) -> float:
        return time.monotonic() - self.wall0

    def power_up(self, limit_s: float = 1.0, settle_s: float = 0.1) -> None:
        """Runs until every board's bootloader has handed over (or has not
        within limit_s: no valid application) and the applications have done
        their power-up work (an erase of the store's spare page stalls the
        CPU 40 ms), as servo_sim is ready with its servos running."""
        until = limit_s
        while self.now_s < until:
            self.now_s += MAX_SLICE_S
            for b in self.boards:
                b.run_until(self.now_s)
            if until == limit_s and all(b.in_application() for b in self.boards):
                until = self.now_s + settle_s
        self.wall0 = time.monotonic() - self.now_s
        self.clock.publish(self.now_s)  # before ready: a host's first look is not at 0

    def run(self) -> None:
        if self.paced:
            self.run_paced()
            return
        while not self.stop_requested:
            ahead = self.now_s - self._wall()
            timeout = min(ahead, 0.002) if ahead > 0 and self._host_waits() is None else 0
            fds = [self.control] + list(self.clients) + self.bus.fds()
            readable, _, _ = select.select(fds, [], [], timeout)
            self.serve_control(readable)
            self.bus.poll_host(self.now_s)
            waits = self._host_waits()
            if waits is not None and self.now_s > self._wall():
                self.wall0 -= self.now_s - self._wall()  # the wall clock skips to the boards'
            if self.now_s > self._wall():
                continue
            self.step(waits)
            self.bus.flush_to_host(self.now_s)  # handed over when the adapter does, not a loop later
            self.clock.publish(self.now_s)
            self.most_behind_s = max(self.most_behind_s, self._wall() - self.now_s)

    def run_paced(self) -> None:
        """Runs while the host waits for a later time or an answer not yet
        given, once every byte it has sent is read; stands still otherwise."""
        while not self.stop_requested:
            waits = self._host_waits()
            may_run = waits is not None and self.clock.host_sent() <= self.bus.host_read
            fds = [self.control] + list(self.clients) + self.bus.fds()
            readable, _, _ = select.select(fds, [], [], 0 if may_run else PACED_POLL_S)
            self.serve_control(readable)
            self.bus.poll_host(self.now_s)
            waits = self._host_waits()
            if waits is None or self.clock.host_sent() > self.bus.host_read:
                continue
            self.step(waits)
            # The clock before the bytes: a host that reads it once it has
            # its answer reads the answer's time, not a slice's before.
            self.clock.publish(self.now_s)
            self.bus.flush_to_host(self.now_s)

    def _host_waits(self):
        """The bus time a host waiting on the clock file wants reached at
        once (None: the wall clock's pace): not yet reached, and, for a host
        waiting for an answer, not yet answered."""
        until_s, answer = self.clock.host_waits()
        received = self.clock.host_received() if self.paced else 0
        if until_s <= self.now_s or (answer and self.bus.host_answered(received)):
            return None
        return until_s

    def step(self, until_s=None) -> None:
        """One slice: every board on to the next byte's end on the bus
        (one a board starts sending included), MAX_SLICE_S or until_s, and
        the bytes that ended by then delivered."""
        target = min(self.now_s + MAX_SLICE_S, max(self.bus.next_event_s(), self.now_s + 1e-7))
        if until_s is not None:
            target = min(target, until_s)
        for b in self.boards:
            b.run_until(target, MAX_SLICE_S)
            # A byte sent: the boards after this one stop at its end; those
            # before it ran on and hear it late, by at most the slice.
            target = min(target, self.bus.next_event_s())
        self.now_s = target
        self.bus.deliver_until(self.now_s)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="vboard", description=__doc__.split("\n\n")[0])
    ap.add_argument("--board", required=True,
                    help=f"a shipped board ({', '.join(sorted(PARTS))}) or a board folder's path")
    ap.add_argument("--build", help="the build tree with the board's images (default: the checkout's)")
    ap.add_argument("--id", type=int, action="append", help="a board with this servo ID (repeat for a bus)")
    ap.add_argument("--tcp", type=int, help="the bus on 127.0.0.1:PORT (0: any free port)")
    ap.add_argument("--link", help="the bus's pseudo-terminal, linked here (not with --tcp)")
    ap.add_argument("--host-link", default="usb",
                    help="how the host's USB-serial adapter hands over the bytes off the wire: usb "
                         "(default), ftdi[:MS] (an FTDI latency timer, default 16 ms) or raw (vboard/usb.py)")
    ap.add_argument("--state", help="the boards' flash files live here (kept across runs)")
    ap.add_argument("--supply", type=float, help="supply, mV (default: the plant's, 7400 for the reference)")
    ap.add_argument("--plant", help="the motor, gears and heat from a plant file (hal/ports/host/plants/*.toml)")
    ap.add_argument("--ambient", type=float, default=25.0, help="ambient temperature, degC")
    ap.add_argument("--app", help="the update image a blank board's slot gets (default: the build's)")
    ap.add_argument("--clock", choices=["wall", "paced"], default="wall",
                    help="paced: run only while the host waits on the clock file (clock_file.py), "
                         "never following the wall clock (default: wall)")
    args = ap.parse_args(argv)
    if args.link and args.tcp is not None:
        ap.error("--link names a pseudo-terminal, and --tcp makes none: give one or the other")
    try:
        Adapter(args.host_link)
    except ValueError as e:
        ap.error(str(e))
    args.id = args.id or [1]
    if args.board not in PARTS:
        folder = Path(args.board)
        if not (folder / "board.h").is_file():
            ap.error(f"--board {args.board}: neither a shipped board ({', '.join(sorted(PARTS))}) "
                     "nor a folder with a board.h")
        args.board = folder.resolve()
        problems = board_facts.check(args.board)
        if problems:
            ap.error("; ".join(problems))
    try:
        build = part_of(args.board).build
    except ValueError as e:
        ap.error(str(e))
    wanted = [images(args.board, args.build)[0]] + ([] if args.app else [images(args.board, args.build)[1]])
    missing = [str(path) for path in wanted if not path.exists()]
    if missing:
        print(f"vboard: no {' or '.join(missing)}: build the {args.board}'s images first "
              f"('cmake --preset {build} && cmake --build --preset {build}')", file=sys.stderr)
        return 2
    try:
        runner = Runner(args)
    except ValueError as e:  # a plant file that is refused says why
        print(f"vboard: {e}", file=sys.stderr)
        return 2
    runner.power_up()
    stuck = [b for b in runner.boards if b.core.locked_up]
    if stuck:
        for b in stuck:
            print(f"vboard: board {b.servo_id} locked up at power-up ({b.state()['pc']}): its flash "
                  f"file in {runner.state_dir} holds no bootloader that runs", file=sys.stderr)
        runner.clock.close()
        return 1
    print(f"vboard: bus {runner.url}")
    if args.link:
        print(f"vboard: link {args.link}")
    print(f"vboard: control 127.0.0.1:{runner.control.getsockname()[1]}")
    print(f"vboard: clock {runner.clock.path}")
    print("vboard: servos " + " ".join(str(i) for i in args.id))
    print("vboard: ready", flush=True)
    # Stopped between two slices, not inside the emulator's hooks.
    signal.signal(signal.SIGTERM, lambda *_: setattr(runner, "stop_requested", True))
    try:
        runner.run()
    except KeyboardInterrupt:
        pass
    finally:
        runner.bus.close()
        runner.clock.close()
        print(f"vboard: stopped ({runner.bus.collisions} collisions)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
