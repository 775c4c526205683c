"""The one thread that owns the bus for `servoctl ui`: it runs servoctl's own
commands (cli.run_command, as the command line would, their output and
refusals word for word), the live table's info rounds and the plots'
samples, one at a time. The page's requests queue here; stop-all jumps the
queue. Results go back through publish (called on this thread)."""
import contextlib
import io
import json
import os
import queue
import shlex
import threading

from .. import cli
from .. import protocol as p
from ..args import build_parser
from ..checks import check_range
from ..errors import EXIT_INTERRUPTED, ServoError
from . import sampling
from .files import Folder

# Commands the page may run as they are: those that end on their own. A
# monitor, a stream and the ui itself run until stopped; sim and image need
# no bus.
RUNNABLE = set(cli.COMMANDS) - {"monitor", "stream", "record", "ui"}
TABLE_EVERY_S = (1.0, 3.0)  # the live table's info round, bus time: idle, plotting


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


class Worker:
    def __init__(self, bus, global_argv: list, publish, files=None):
        self.bus, self.global_argv, self.publish = bus, list(global_argv), publish
        self.files = Folder(files if files is not None else os.getcwd())  # the only files the page names
        self.jobs = queue.Queue()
        self.urgent = queue.Queue()  # stop-all
        self.known = []     # the live table's IDs (after a scan)
        self.plot_ids = []  # sampled while the queue is empty
        self.sampler = None
        self.stopping = threading.Event()
        self.interrupt = threading.Event()  # stop-all: the running command ends at its next bus step
        self.busy, self.current = False, None
        for name in ("request", "send", "sleep", "gather"):
            setattr(bus, name, self._interruptible(getattr(bus, name)))
        self.thread = threading.Thread(target=self._loop, name="servoctl-ui-bus", daemon=True)
        self._next_table = 0.0

    def start(self):
        self.thread.start()

    def stop(self):
        """Ctrl-C: a command still running ends at its next bus step."""
        self.stopping.set()
        self.interrupt.set()
        self.jobs.put(None)
        self.thread.join(timeout=5)

    def submit(self, fn, *a):
        self.jobs.put((fn, a))

    def submit_urgent(self, fn, *a):
        self.urgent.put((fn, a))
        if self.busy and self.current != self.stop_all:
            self.interrupt.set()
        self.jobs.put(("wake", ()))

    def _interruptible(self, step):
        def step_unless_stopped(*a, **kw):
            if self.interrupt.is_set():
                raise KeyboardInterrupt
            return step(*a, **kw)
        return step_unless_stopped

    # What the page asks for -------------------------------------------------

    def run(self, argv: list, tag=None) -> dict:
        """One servoctl command, parsed and run as the command line does;
        its output, and an error as servoctl words it ("servoctl: error: ...")."""
        if not argv or argv[0] not in RUNNABLE:
            msg = f"servoctl ui runs these commands: {', '.join(sorted(RUNNABLE))}; not {argv[:1]}"
            return self._result(tag, argv, 2, "", f"servoctl: error: {msg}")
        out, err = _Lines(lambda line: self.publish({"type": "line", "tag": tag, "text": line})), _Lines(
            lambda line: self.publish({"type": "line", "tag": tag, "text": line, "err": True}))
        code, staging = 0, None
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                args = build_parser().parse_args(self.global_argv + list(argv))
                if args.command == "config":
                    cli.args_.config_operands(args)
                staging = self.files.confine(args)
                out.shown = err.shown = staging.shown
                args.on_progress = self._progress(tag)
                code = cli.run_command(self.bus, args)
                if code == 0:
                    staging.write_out()
            except KeyboardInterrupt:
                print("servoctl: interrupted by stop-all", file=err)
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
        self.known = sorted({f["id"] for f in found if f["mode"] == "application" and not f["shared"]})
        self.publish({"type": "scan", "found": found, "err": r["err"], "code": r["code"]})
        self.table()

    def table(self):
        """Every known servo's info (servoctl info --json), or why it is
        silent; a servo being plotted is left to its samples."""
        rows = []
        for servo_id in (i for i in self.known if i not in self.plot_ids):
            r = self.run_quiet(["info", str(servo_id), "--json"])
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

    def items(self, servo_id: int):
        self.publish({"type": "items", "id": servo_id, "items": sampling.items_of(self.bus, servo_id)})

    def plot(self, ids: list):
        ids = [int(i) for i in ids]
        for servo_id in ids:
            check_range("servo ID", servo_id, 0, p.MAX_ID)
        self.plot_ids = ids
        self.sampler = sampling.Sampler(self.bus, self.plot_ids) if self.plot_ids else None
        self.publish({"type": "plotting", "ids": self.plot_ids})

    def stop_all(self, mode: str):
        """Every known servo damped or released (servoctl stop ID --mode);
        the commands still queued are dropped, unrun."""
        self.interrupt.clear()
        while True:
            try:
                job = self.jobs.get_nowait()
            except queue.Empty:
                break
            if job and job[0] == self.run:
                argv, tag = job[1]
                self._result(tag, argv, EXIT_INTERRUPTED, "", "servoctl ui: not run: stop-all came first")
        ids = self.known or self.plot_ids
        failed = []
        try:  # every servo at this baud rate first: one not in the last scan (none yet, a
            # shared or a new ID) is stopped too; then each known one, its answer checked
            method = {"release": 0x10, "damping": 0x12}[mode]  # as Servo.stop's
            self.bus.send(p.STOP_ON_CONTROL, p.encode_request(p.STOP_ON_CONTROL, p.BROADCAST, method, 0))
        except ServoError as e:
            failed.append(f"broadcast stop: {e}")
        said = [self.run_quiet(["stop", str(i), "--mode", mode]) for i in ids]
        failed += [r["err"] for r in said if r["code"]]
        self.interrupt.clear()  # one set as this began: it interrupts nothing later
        self.publish({"type": "stopped", "mode": mode, "ids": ids, "failed": failed})

    # The thread -------------------------------------------------------------

    def _loop(self):
        while not self.stopping.is_set():
            while not self.urgent.empty():
                self._do(self.urgent.get())
            try:
                job = self.jobs.get(timeout=0 if self.plot_ids else 0.2)
            except queue.Empty:
                job = "idle"
            if job is None:
                return
            if job == "idle":
                try:
                    self._idle()
                except KeyboardInterrupt:
                    self.interrupt.clear()  # stop-all, a moment late: it runs next
                except Exception as e:  # noqa: BLE001 - a lost link: the page hears it, stop-all still runs
                    self.publish({"type": "error", "text": f"servoctl ui: {type(e).__name__}: {e}"})
                    self.stopping.wait(1.0)
            elif job[0] != "wake":
                self._do(job)

    def _do(self, job):
        fn, a = job
        self.busy, self.current = True, fn
        try:
            fn(*a)
        except KeyboardInterrupt:
            self.publish({"type": "error", "text": "servoctl ui: interrupted by stop-all"})
        except Exception as e:  # noqa: BLE001 - the page hears it; the thread goes on
            self.publish({"type": "error", "text": f"servoctl ui: {type(e).__name__}: {e}"})
        finally:
            self.busy = False

    def _idle(self):
        if self.sampler is not None:
            rows = self.sampler.take()
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
