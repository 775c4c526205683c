"""The one thread that owns the bus for `servoctl ui`: it runs servoctl's own
commands (cli/commands.py's run_command, as the command line would, their output and
refusals word for word), the live table's info rounds and the plots'
samples, one at a time. The page's requests queue here (QUEUE_MAX at
most); stop-all jumps the queue and interrupts what runs (preempt.py).
Results go back through publish (called on this thread)."""
import collections
import contextlib
import importlib
import io
import json
import os
import shlex
import threading

from ..cli import args as args_, commands
from .. import protocol as p
from ..cli.args import build_parser
from ..checks import check_range
from ..errors import EXIT_INTERRUPTED, NoReply, ServoError
from ..servo import Servo
from . import sampling
from .files import Folder
from .preempt import STOP_METHOD, Preemption, stop_at_every_rate

# Commands the page may run as they are: those that end on their own. A
# monitor, a stream and the ui itself run until stopped; sim and image need
# no bus.
RUNNABLE = set(commands.COMMANDS) - {"monitor", "stream", "record"}
TABLE_EVERY_S = (1.0, 3.0)  # the live table's info round, bus time: idle, plotting
QUEUE_MAX = 64  # page actions waiting; more are refused (a page gone wild, a script)
NOT_RUN = "servoctl ui: not run: stop-all came first"
# An update stopped part-way: a servo it had switched over waits in its bootloader.
UPDATE_CUT = ("servoctl ui: the update stopped part-way: a servo it had switched to its bootloader is left "
              "there (a scan shows it so); run the update again to install an application")
# What identify, tune, calibrate and update load on first use (scipy takes
# a second): loaded as the ui starts, on a thread of their own, not on the
# bus thread in the middle of a command.
SLOW_IMPORTS = ("servoctl.cli.drive_report", "servoctl.calibrate", "servoctl.tune", "servoctl.update",
                "servoctl.cli.bench", "servoctl.cli.console")


# The Motion view's jog: a move of at most the slider's step (1 deg,
# index.html's #jog) from the angle the servo is at, read first, and the
# 0.5 deg a move may end off its target (outcome.TOLERANCE_DEG). A slider
# that stood anywhere else (at 0 when the page opened) threw the horn there
# at full speed.
JOG_MAX_DEG = 1.5
JOG_MS = 200


class QueueFull(Exception):
    pass


class _Lines(io.TextIOBase):
    """stdout or stderr of a command: each whole line goes to the page as it
    comes (calibrate, tune and update print their steps)."""

    def __init__(self, say):
        self.say, self.part, self.all = say, "", []
        self.shown = str  # the staged copies' names as the folder's (files.Staging.shown)

    def writable(self):
        return True

    def isatty(self):
        return False

    def write(self, text):
        self.part += text
        while "\n" in self.part:
            line, self.part = self.part.split("\n", 1)
            line = self.shown(line)
            self.all.append(line)
            self.say(line)
        return len(text)

    def text(self) -> str:
        return "\n".join(self.all + ([self.shown(self.part)] if self.part else []))



def _option(argv: list, name: str):
    """A global option's value as the page's commands are given it, or None."""
    return argv[argv.index(name) + 1] if name in argv[:-1] else None


class Worker:
    def __init__(self, bus, global_argv: list, publish, files=None):
        self.bus, self.global_argv, self.publish = bus, list(global_argv), publish
        self.files = Folder(files if files is not None else os.getcwd())  # the only files the page names
        self.jobs = collections.deque()    # the page's requests, QUEUE_MAX at most
        self.urgent = collections.deque()  # stop-all, and what a closed tab leaves
        self.cond = threading.Condition()  # guards both, current, and the interrupt's setting
        self.known = []     # the live table's IDs (after a scan)
        self.stops = 0      # STOP ALLs so far: a jog asked before the last is not run
        self.plot_ids = []  # sampled while the queue is empty
        self.sampler = None
        self.stopping = threading.Event()
        self.before_stop = 0  # jobs queued when the latest stop was asked for
        # A tab is open (server.Page sets it as the last one closes): with
        # none, neither the live table's rounds nor the plots' samples go on
        # the bus, so a servo's bus watchdog (item 64) is fed by nobody and
        # acts. Before the first tab there is nothing to poll: no scan yet.
        self.watched = True
        self.preempt = Preemption(bus)  # the running command ends at its next look at the port
        self.current = None
        self.thread = threading.Thread(target=self._loop, name="servoctl-ui-bus", daemon=True)
        self._next_table = 0.0

    def start(self):
        threading.Thread(target=_import_slow_parts, name="servoctl-ui-imports", daemon=True).start()
        self.thread.start()

    def stop(self):
        """Ctrl-C: a command still running ends at its next bus step."""
        with self.cond:
            self.stopping.set()
            self.preempt.interrupt("the ui stopping")
            self.cond.notify()
        self.thread.join(timeout=5)
        self.preempt.close()

    def submit(self, fn, *a):
        """A page's request, run after those before it; QueueFull if
        QUEUE_MAX wait already."""
        with self.cond:
            if len(self.jobs) >= QUEUE_MAX:
                raise QueueFull(f"servoctl ui: {QUEUE_MAX} actions are waiting for the bus: this one is "
                                f"refused (wait for them, or STOP ALL drops them)")
            self.jobs.append((fn, a))
            self.cond.notify()

    def stop_now(self, mode: str):
        """STOP ALL (on the server's thread): what runs interrupted, the
        broadcast stop on the wire at once (preempt.py), then stop_all
        before anything queued."""
        with self.cond:
            self.stops += 1
            self.before_stop = len(self.jobs)  # those stop_all answers "not run"; later ones run
            if self.current != self.stop_all:
                self.preempt.interrupt("stop-all")
            if (self.stop_all, (mode,)) not in self.urgent:
                self.urgent.append((self.stop_all, (mode,)))
            self.cond.notify()
        # After the interrupt: a command's write that follows this on the
        # wire sees it (preempt.py's lock) and is not sent.
        self.preempt.broadcast_stop(mode)

    def abandon(self, mode: str = None):
        """The driving tab closed: its queued requests dropped, its command
        interrupted, its plot's sampling stopped; given a mode (its STOP
        ALL's), every servo stopped as STOP ALL stops them: what it set
        moving does not go on without it."""
        with self.cond:
            self.jobs.clear()
            self.before_stop = 0  # the next tab's requests, made after this, run after its stop
            if self.current != self.stop_all:
                self.preempt.interrupt("the tab that asked for it closing")
            self.urgent.append((self.plot, ([],)))
            if mode is not None and (self.stop_all, (mode,)) not in self.urgent:
                self.urgent.append((self.stop_all, (mode,)))
            self.cond.notify()

    # What the page asks for -------------------------------------------------

    def run(self, argv: list, tag=None) -> dict:
        """One servoctl command, parsed and run as the command line does;
        its output, and an error as servoctl words it ("servoctl: error: ...")."""
        if not argv or argv[0] not in RUNNABLE:
            msg = f"servoctl ui runs these commands: {', '.join(sorted(RUNNABLE))}; not {argv[:1]}"
            return self._result(tag, argv, 2, "", f"servoctl: error: {msg}")
        out, err = _Lines(lambda line: self.publish({"type": "line", "tag": tag, "text": line})), _Lines(
            lambda line: self.publish({"type": "line", "tag": tag, "text": line, "err": True}))
        code, staging, args = 0, None, None
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                args = build_parser().parse_args(self.global_argv + list(argv))
                if args.command == "config":
                    args_.config_operands(args)
                staging = self.files.confine(args)
                out.shown = err.shown = staging.shown
                args.on_progress = self._progress(tag)
                code = commands.run_command(self.bus, args)
                if not code:  # 0, or None: what a command that ends well may return
                    staging.write_out()
            except KeyboardInterrupt:
                print(f"servoctl: interrupted by {self.preempt.why}", file=err)
                if args is not None and args.command == "update":
                    print(UPDATE_CUT, file=err)
                code = EXIT_INTERRUPTED
            except SystemExit as e:  # argparse's usage error, printed to err
                code = e.code if isinstance(e.code, int) else 2
            except ServoError as e:
                print(f"servoctl: error: {e}", file=err)
                code = e.exit_code
            except Exception as e:  # noqa: BLE001 - an argument check's (ArgumentTypeError)
                print(f"servoctl: error: {e}", file=err)
                code = 2
            finally:
                if staging is not None:
                    staging.close()
        return self._result(tag, argv, code, out.text(), err.text())

    def jog(self, servo_id: int, angle: float, stops: int, tag=None) -> dict:
        """The jog slider's angle: moved to in JOG_MS if it is within
        JOG_MAX_DEG of where the servo is (read now), else refused; not run
        if a STOP ALL came since the page last heard of one (stops: the
        count it has; a drag goes on sending through another tab's stop).
        The page asks for the angle after it (angle()) and puts the slider
        there."""
        argv = ["move", str(servo_id), f"{angle:g}", "--interval", str(JOG_MS), "--wait"]
        if stops < self.stops:
            return self._result(tag, argv, EXIT_INTERRUPTED, "", "servoctl ui: not run: STOP ALL came after this "
                                "jog was asked; let go of the slider to jog again")
        try:
            at = Servo(self.bus, servo_id).multi_turn_angle()[0] / 10
        except KeyboardInterrupt:  # its answer all the same: the page waits for it
            return self._result(tag, argv, EXIT_INTERRUPTED, "", f"servoctl: interrupted by {self.preempt.why}")
        except ServoError as e:
            return self._result(tag, argv, e.exit_code, "", f"servoctl: error: {e}")
        if abs(angle - at) > JOG_MAX_DEG:
            return self._result(tag, argv, 2, "", f"servoctl ui: a jog moves {JOG_MAX_DEG:g} deg at most from where "
                                f"the servo is: servo {servo_id} is at {at:.1f} deg, not near {angle:g}; not moved "
                                f"(Move takes it farther)")
        return self.run(argv, tag)

    def angle(self, servo_id: int, tag=None):
        """Tells the page where servo_id is ({"type": "angle"}: its
        multi-turn angle in deg, or None and why); returns it."""
        try:
            deg, why = Servo(self.bus, servo_id).multi_turn_angle()[0] / 10, None
        except ServoError as e:
            deg, why = None, f"servoctl: error: {e}"
        self.publish({"type": "angle", "id": servo_id, "tag": tag, "angle_deg": deg, "why": why})
        return deg

    def _progress(self, tag):
        """update's progress, a line each tenth of an image."""
        said = {}

        def say(servo_id, done, total):
            tenth = done * 10 // max(total, 1)
            if said.get(servo_id) != tenth:
                said[servo_id] = tenth
                self.publish({"type": "progress", "tag": tag, "id": servo_id, "done": done, "total": total,
                              "text": f"servo {servo_id}: {done} of {total} B"})
        return say

    def _result(self, tag, argv, code, out, err) -> dict:
        msg = {"type": "result", "tag": tag, "argv": argv, "command": "servoctl " + shlex.join(argv),
               "code": code, "out": out, "err": err}
        self.publish(msg)
        return msg

    def scan(self, all_bauds: bool, tag=None):
        r = self.run(["scan", "--json"] + (["--all-bauds"] if all_bauds else []), tag)
        try:
            found = json.loads(r["out"].splitlines()[-1]) if r["out"] else []
        except (ValueError, IndexError):
            found = []
        ids = {f["id"] for f in found if f["mode"] == "application" and not f["shared"]}
        if r["code"] == EXIT_INTERRUPTED:  # a part of the bus: those known before are kept for stop-all
            ids |= set(self.known)
        self.known = sorted(ids)
        self.publish({"type": "scan", "found": found, "err": r["err"], "code": r["code"]})
        self.preempt.check()
        self.table()

    def table(self):
        """Every known servo's info (servoctl info --json), or why it is
        silent; those being plotted too (the round comes every 3 s then)."""
        rows = []
        for servo_id in self.known:
            r = self.run_quiet(["info", str(servo_id), "--json"])
            self.preempt.check()  # interrupted: no row is "gone" for it
            if r["code"] == 0:
                rows.append(json.loads(r["out"]))
            else:
                rows.append({"id": servo_id, "gone": True, "why": r["err"].removeprefix("servoctl: error: ")})
        self.publish({"type": "table", "rows": rows, "t_s": round(self.bus.clock(), 3)})

    def run_quiet(self, argv):
        publish, self.publish = self.publish, lambda msg: None
        try:
            return self.run(argv)
        finally:
            self.publish = publish

    def items(self, servo_id: int, tag=None):
        try:
            self.publish({"type": "items", "id": servo_id, "tag": tag,
                          "items": sampling.items_of(self.bus, servo_id)})
        except NoReply as e:  # said once, not as each item missing
            self.publish({"type": "items", "id": servo_id, "tag": tag, "items": [], "silent": str(e)})

    def plot(self, ids: list, tag=None):
        ids = list(dict.fromkeys(int(i) for i in ids))  # each once: a page's list, not a Sync Monitor of 10 000
        for servo_id in ids:
            check_range("servo ID", servo_id, 0, p.MAX_ID)
        self.plot_ids = ids
        self.sampler = sampling.Sampler(self.bus, self.plot_ids) if self.plot_ids else None
        self.publish({"type": "plotting", "ids": self.plot_ids})

    def stop_all(self, mode: str):
        """Every known servo damped or released (servoctl stop ID --mode);
        the commands still queued are dropped, unrun. stop_now's broadcast
        is on the wire already; it goes again here, at the host's own rate
        (a scan of all rates may have been at another)."""
        failed = []
        try:  # every servo at this baud rate first: one not in the last scan (none yet, a
            # shared or a new ID) is stopped too; then each known one, its answer checked
            self.bus.send(p.STOP_ON_CONTROL, p.encode_request(p.STOP_ON_CONTROL, p.BROADCAST,
                                                              STOP_METHOD[mode], 0))
        except ServoError as e:
            failed.append(f"broadcast stop: {e}")
        # Before the servos one by one: a servo left at another rate (a baud
        # change from the page) waited out each silent one's timeout (1-1.7 s).
        host = self.bus.serial.baudrate
        swept = stop_at_every_rate(self.bus, _option(self.global_argv, "--sim-control"), mode)
        failed += swept or []
        with self.cond:  # those queued before the stop was asked for; a tab's after it run
            dropped = [self.jobs.popleft() for _ in range(min(self.before_stop, len(self.jobs)))]
            self.before_stop = 0
        for fn, a in dropped:  # each answered, where the page shows that action's output
            if fn == self.run:
                argv, tag = a
                self._result(tag, argv, EXIT_INTERRUPTED, "", NOT_RUN)
            elif fn == self.jog:  # a move not made, as a stopped one: the page holds its slider
                self._result(a[-1], ["move", str(a[0]), f"{a[1]:g}"], EXIT_INTERRUPTED, "", NOT_RUN)
            else:
                self.publish({"type": "error", "op": fn.__name__, "tag": a[-1] if len(a) > 1 else None,
                              "text": NOT_RUN})
        ids = self.known or self.plot_ids
        said = [self.run_quiet(["stop", str(i), "--mode", mode]) for i in ids]
        failed += [r["err"] for r in said if r["code"]]
        if swept is not None and any(r["code"] for r in said):
            failed.append(f"the broadcast was sent at every rate: a servo that did not answer at {host} baud "
                          f"stops if it speaks another and the frame reached it (no servo answers a broadcast)")
        answered = [i for i, r in zip(ids, said) if not r["code"]]
        self.publish({"type": "stopped", "mode": mode, "ids": ids, "answered": answered, "failed": failed,
                      "stops": self.stops})

    # The thread -------------------------------------------------------------

    def _loop(self):
        while True:
            with self.cond:
                if not (self.urgent or self.jobs or (self.plot_ids and self.watched) or self.stopping.is_set()):
                    self.cond.wait(0.2)
                if self.stopping.is_set():
                    return
                job = self.urgent.popleft() if self.urgent else self.jobs.popleft() if self.jobs else None
                # What the interrupt was for has ended; one set after this (under
                # the lock) comes with its own urgent job and interrupts this one.
                self.preempt.clear()
                self.current = job[0] if job else self._idle
            try:
                if job is None:
                    self._idle()
                else:
                    job[0](*job[1])
            except KeyboardInterrupt:
                if job is not None:
                    self.publish({"type": "error", "text": f"servoctl ui: interrupted by {self.preempt.why}"})
            except Exception as e:  # noqa: BLE001 - the page hears it; the thread goes on, stop-all still runs
                self.publish({"type": "error", "text": f"servoctl ui: {type(e).__name__}: {e}"})
                if job is None:  # a lost link: not a round every 0.2 s
                    self.stopping.wait(1.0)
            finally:
                self.current = None

    def _idle(self):
        if not self.watched:  # no tab: nothing on the bus (the servos' watchdogs act)
            return
        sampler = self.sampler  # plot() replaces it on this thread only
        if sampler is not None:
            rows = sampler.take()
            if rows:
                self.publish({"type": "samples", "rows": rows})
        try:
            now = self.bus.clock()
        except ServoError as e:
            self.publish({"type": "error", "text": f"servoctl ui: {e}"})
            self.stopping.wait(1.0)
            return
        if self.known and now >= self._next_table:
            self._next_table = now + TABLE_EVERY_S[bool(self.plot_ids)]
            self.table()


def _import_slow_parts():
    for name in SLOW_IMPORTS:
        try:
            importlib.import_module(name)
        except ImportError:  # an extra not installed: the command says so when asked
            pass
