"""Starts servo_sim (the firmware on simulated servos), or a virtual board,
and talks to its fault-injection channel: `servoctl sim` and the Python API
(docs/simulator.md). The tests' own launchers (QEMU, the repository's
plant files) are tools/tests/launchers.py's."""
import math
import mmap
import os
from pathlib import Path
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

from . import extras
from .protocol import Bus, LinkError, ServoError
from .sim_control import control_command, fields as _fields  # noqa: F401 (control_command: link_rate's)

# The folder servoctl is installed in (tools/ of a checkout): vboard,
# shipped with it, is imported from there by the virtual board's process.
PACKAGES = Path(__file__).resolve().parent.parent
# Host seconds a simulator's clock may stand still before a wait gives up
# on it (a simulator falls behind on a busy PC; it does not stop).
STALLED_S = 30.0
# Host seconds a simulator may take to start: a virtual board (Python, unicorn,
# its images) takes a few on an idle PC, over 20 on a loaded CI machine (scripts/stress.sh).
READY_S = 60
_CLOCK_US = struct.Struct("<Q")  # servo_sim's clock file: microseconds
HOST_BUILD = Path("build", "host", "firmware", "boards", "host_sim", "servo_sim")  # of a checkout


def checkout_binary(start=None):
    """HOST_BUILD in start (the working directory if None) or the nearest
    folder above it that has one: the host build of the checkout servoctl
    is run in, wherever servoctl itself is installed; None if none has."""
    here = Path(start or os.getcwd()).resolve()
    return next((f / HOST_BUILD for f in (here, *here.parents) if (f / HOST_BUILD).exists()), None)


def find_binary() -> Path:
    """servo_sim: $SERVO_SIM, else the host build of the checkout servoctl
    is run in (checkout_binary), else the PATH (docs/simulator.md)."""
    if "SERVO_SIM" in os.environ:
        candidates = [Path(os.environ["SERVO_SIM"])]
    else:
        in_checkout, on_path = checkout_binary(), shutil.which("servo_sim")
        candidates = [p for p in (in_checkout, on_path and Path(on_path)) if p] or [HOST_BUILD]
    for path in candidates:
        if path.exists():
            return path
    raise ServoError(f"no simulator at {candidates[0]} (nor in a folder above {os.getcwd()}): build it with "
                     f"'cmake --preset host && cmake --build --preset host' and run servoctl in the "
                     f"checkout, put servo_sim on the PATH, or point SERVO_SIM at it")


class _Child:
    """A child process started by start(), stopped on leaving a with-block."""

    process = None

    def start(self):
        raise NotImplementedError

    def stop(self) -> str:
        """Stops it; returns what it wrote to stderr."""
        err = _stop(self.process)
        self.process = None
        return err

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


class Simulator(_Child):
    """servo_sim as a context manager. The bus is a TCP port (pyserial
    socket://) unless tcp=False, then a pseudo-terminal (optionally linked)."""

    def __init__(self, ids=(1,), tcp=True, link=None, state_dir=None, supply_mv=None,
                 ambient_c=None, tcp_port=None, rx=None, board=None, app_image=None, nice=None,
                 cpu=None, plant=None, host_link=None, fast=False, paced=False, build=None):
        self.ids = list(ids)
        self.tcp = tcp or tcp_port is not None
        self.tcp_port = tcp_port
        self.link = link
        self._own_state = state_dir is None
        self.state_dir = state_dir or tempfile.mkdtemp(prefix="servo-sim-")
        self.supply_mv = supply_mv
        self.ambient_c = ambient_c
        self.rx = rx  # "dma" (default) or "interrupt": how the servos' port receives
        self.cpu = cpu  # "m3" (default) or "m0": whose time a pass, a tick, an answer take
        self.board = board  # None: servo_sim; else a virtual board (tools/vboard): a name or a folder's path
        self.app_image, self.build = app_image, build  # a virtual board's slot and build tree, if not the checkout's
        self.plant = plant  # a plant file (hal/ports/host/plants); None: the reference servo
        self.plant_name = None  # the plant's name, as servo_sim prints it
        # How the host's USB-serial adapter hands over the bytes off the
        # wire: "usb" (the simulators' default), "ftdi", "ftdi:MS" or "raw"
        # (servo_sim --help, docs/simulator.md). None: the default.
        self.host_link = host_link
        # The tests': servo_sim's clock runs as fast as it can while this
        # host waits on it (sleep, wait_until, a bus's answers), bounded by
        # run_ahead_to; it follows the wall clock otherwise (sim_clock.h).
        self.fast = fast
        # The tests' where the host paces an experiment (identify): servo_sim
        # runs only while this host waits on it, and never follows the wall
        # clock, so a loaded PC cannot change what the servos see
        # (servo_sim --clock paced; sim_clock.h).
        self.paced = paced
        # A niceness for the simulator (below 0 needs root): a client that
        # times its answers on the wall clock (the maker's SDK) then meets
        # a servo that keeps up on a loaded PC. None: as started.
        self.nice = nice
        self.process, self.preexec = None, None  # preexec: run in the child before servo_sim (sim_arms.py)
        self.url = None
        self.control_port = None
        self._clock_seen, self._clock_moved_at = None, 0.0
        self._clock_conn = None
        self._clock_lock = threading.Lock()
        self._clock_map = None  # servo_sim's clock file, mapped (sim_clock.h)
        self._sent_bytes = 0  # on the bus, in all: a paced servo_sim's offset 16
        self._read_bytes = 0  # off the bus, in all: its offset 24
        self._read_at_send = 0  # _read_bytes when the host last sent

    @classmethod
    def running(cls, control_port: int) -> "Simulator":
        """A simulator another process started (`servoctl sim`, a virtual
        board), reached by its control port: its clock (clock_s) for a
        Bus, and control. stop() closes the connection, nothing else."""
        sim = cls(state_dir=os.devnull)  # not made here: not removed
        sim.control_port = control_port
        return sim

    def start(self) -> "Simulator":
        if self.board is not None:
            if self.rx is not None or self.cpu is not None:
                raise ServoError("a virtual board runs as its MCU does: --rx and --cpu are servo_sim's")
            extras.require("unicorn", "cmsis_svd")  # the child's, which would die with its traceback
            cmd = [sys.executable, "-m", "vboard", "--board", self.board, "--state", self.state_dir]
            cmd += ["--app", str(self.app_image)] if self.app_image is not None else []
            cmd += ["--build", str(self.build)] if self.build is not None else []
        else:
            cmd = [str(find_binary()), "--state", self.state_dir]
        for i in self.ids:
            cmd += ["--id", str(i)]
        if self.tcp:
            # 0: the simulator takes a free port itself and prints it (no
            # other process can take it between a look and the bind).
            cmd += ["--tcp", str(self.tcp_port or 0)]
        if self.link:
            cmd += ["--link", str(self.link)]
        if self.supply_mv is not None:
            cmd += ["--supply", str(self.supply_mv)]
        if self.ambient_c is not None:
            cmd += ["--ambient", str(self.ambient_c)]
        if self.plant is not None:
            cmd += ["--plant", str(self.plant)]
        if self.host_link is not None:
            cmd += ["--host-link", self.host_link]
        if self.paced:
            cmd += ["--clock", "paced"]
        if self.rx is not None:
            cmd += ["--rx", self.rx]
        if self.cpu is not None:
            cmd += ["--cpu", self.cpu]
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(PACKAGES)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
        self.process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True, env=env, preexec_fn=self.preexec)
        try:
            return self._until_ready(cmd)
        except BaseException:
            self.stop()  # a start that failed, or was interrupted, leaves nothing running
            raise

    def _until_ready(self, cmd) -> "Simulator":
        if self.nice is not None:
            try:
                os.setpriority(os.PRIO_PROCESS, self.process.pid, self.nice)
            except OSError:
                pass  # not permitted: it runs as started
        deadline = time.monotonic() + READY_S
        while time.monotonic() < deadline:
            line = self.process.stdout.readline()
            if not line:
                err = self.process.stderr.read()
                raise ServoError(f"{cmd[0] if self.board is None else 'vboard'} exited: {err.strip()}")
            words = line.split()
            if words[1:2] == ["bus"]:
                self.url = words[2]
            elif words[1:2] == ["plant"]:
                self.plant_name = " ".join(words[2:])
            elif words[1:2] == ["control"]:
                self.control_port = int(words[2].rsplit(":", 1)[1])
            elif words[1:2] == ["clock"]:
                self._map_clock(words[2])
            elif words[1:2] == ["ready"]:
                return self
        raise ServoError(f"{'servo_sim' if self.board is None else 'vboard'} did not become ready within "
                         f"{READY_S} s")

    def stop(self) -> str:
        """Stops servo_sim; a state folder it made itself goes with it."""
        if self._clock_conn is not None:
            self._clock_conn.close()
            self._clock_conn = None
        if self._clock_map is not None:
            self._clock_map.close()
            self._clock_map = None
        err = super().stop()
        if self._own_state:
            shutil.rmtree(self.state_dir, ignore_errors=True)
        return err

    def bus(self, **kw) -> Bus:
        """A Bus to the simulated servos that waits on the simulated clock."""
        return Bus(self.url, clock=self.clock_s, **kw)

    def control(self, line: str) -> str:
        """Sends one control command; returns the reply."""
        return control_command(self.control_port, line)

    def clock_s(self) -> float:
        """The simulated clock, seconds. The servos and their models run on
        it; it follows the wall clock and falls behind it on a busy PC. A
        clock that stands still for STALLED_S host seconds is a hung
        simulator (a loaded PC slows it, it never stops it): ServoError."""
        if self._clock_map is not None:
            now = self._read_mapped_clock()
            if now == self._clock_seen and self.process.poll() is not None:
                # The file outlives the process: asked, the control port would refuse.
                raise LinkError(f"servo_sim has stopped (exit status {self.process.returncode}): "
                                f"its clock no longer moves")
        else:
            now = _fields(self._ask_clock())["sim_ms"] / 1000.0
        if now != self._clock_seen:
            self._clock_seen, self._clock_moved_at = now, time.monotonic()
        elif time.monotonic() - self._clock_moved_at > STALLED_S:
            raise ServoError(f"servo_sim's clock stood still for {STALLED_S:.0f} s: it stopped, or runs --clock paced")
        return now

    def _map_clock(self, path: str) -> None:
        """The clock servo_sim publishes in a file (sim_clock.h): read in a
        microsecond, where asking the control port takes some 25 us of
        host time, which is simulated time on an idle PC."""
        if self._clock_map is not None:
            self._clock_map.close()  # a restarted simulator's file is mapped anew
        self._sent_bytes = self._read_bytes = self._read_at_send = 0
        try:
            writes = self.fast or self.paced
            with open(path, "r+b" if writes else "rb") as f:
                self._clock_map = mmap.mmap(f.fileno(), 32 if self.paced else 16 if writes else 8,
                                            access=mmap.ACCESS_WRITE if writes else mmap.ACCESS_READ)
        except (OSError, ValueError):
            self._clock_map = None  # the control port still answers

    def _read_mapped_clock(self) -> float:
        # Twice alike: a copy that overlapped the simulator's store is read again.
        while True:
            first = _CLOCK_US.unpack_from(self._clock_map)[0]
            if _CLOCK_US.unpack_from(self._clock_map)[0] == first:
                return first / 1e6

    def _ask_clock(self) -> str:
        """'clock' on one control connection kept open: the bus reads the
        clock at every answer, and a connection each time cost more host
        time (which is simulated time on an idle PC) than the answer."""
        with self._clock_lock:
            for attempt in (1, 2):
                try:
                    if self._clock_conn is None:
                        self._clock_conn = socket.create_connection(("127.0.0.1", self.control_port),
                                                                    timeout=2.0)
                        self._clock_conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                    self._clock_conn.sendall(b"clock\n")
                    reply = b""
                    while not reply.endswith(b"\n"):
                        chunk = self._clock_conn.recv(256)
                        if not chunk:
                            raise OSError("closed")
                        reply += chunk
                    return reply.decode()
                except OSError:
                    if self._clock_conn is not None:
                        self._clock_conn.close()
                    self._clock_conn = None
                    if attempt == 2:
                        return self.control("clock")  # says what went wrong
        return ""

    def sleep(self, seconds: float) -> None:
        """Returns once the simulated clock has moved on by seconds: what
        time.sleep would be on an idle PC, whatever the load."""
        self._wait(lambda: False, seconds, seconds if self._runs_ahead() else 0.005)

    def wait_until(self, predicate, timeout_s: float, step_s: float = 0.005) -> float:
        """Polls predicate until it is true; returns the simulated seconds
        waited, or fails once timeout_s of simulated time have passed."""
        met, waited = self._wait(predicate, timeout_s, step_s)
        if not met:
            raise AssertionError(f"not within {timeout_s} s of simulated time")
        return waited

    def _wait(self, predicate, timeout_s: float, step_s: float):
        """(predicate met, simulated seconds waited)."""
        start = self.clock_s()
        end = start + timeout_s
        if self._runs_ahead():
            end = on_us_grid(end)  # where it stops: reached, not a float's width short
        while True:
            if predicate():
                return True, self.clock_s() - start
            now = self.clock_s()
            waited = now - start
            if now >= end:
                return False, waited
            if not self._runs_ahead():
                time.sleep(min(step_s, timeout_s - waited))
                continue
            # The predicate is looked at as often in simulated time.
            until = min(on_us_grid(now + step_s), end)
            self.run_ahead_to(until)
            while self.clock_s() < until:
                time.sleep(0.0002)

    def _runs_ahead(self) -> bool:
        return (self.fast or self.paced) and self._clock_map is not None and self._clock_map.size() >= 16

    @property
    def bus_sent(self):
        """What a Bus on this simulator's clock tells how many bytes it has
        sent (a paced simulator waits until it has read them all)."""
        return self._host_sent if self.paced and self._clock_map is not None else None

    def _host_sent(self, count: int) -> None:
        self._sent_bytes += count
        self._read_at_send = self._read_bytes
        _CLOCK_US.pack_into(self._clock_map, 16, self._sent_bytes)

    @property
    def bus_read(self):
        """What a Bus on this simulator's clock tells of the bytes it reads,
        and when it has looked at all of them and waits for more (a Sync
        Monitor's answers past an absent servo): a paced simulator then runs
        on from an answer it has given."""
        return self._host_read if self.paced and self._clock_map is not None else None

    def _host_read(self, count: int, waits_for_more: bool = False) -> None:
        self._read_bytes += count
        # Only once bytes came since the host last sent (docs/simulator.md: not the last answer's)
        if waits_for_more and self._read_bytes > self._read_at_send:
            _CLOCK_US.pack_into(self._clock_map, 24, self._read_bytes)

    @property
    def bus_run_ahead(self):
        """What a Bus on this simulator's clock tells where it waits for."""
        return self.run_ahead_to if self.fast or self.paced else None

    def run_ahead_to(self, until_s: float, answer: bool = False) -> None:
        """A fast simulator's clock runs as fast as it can up to until_s
        (simulated seconds), with answer only until it has answered the
        host's last bytes, and follows the wall clock from there (a paced
        one stands still there)."""
        if self._runs_ahead():
            flags = answer << 63
            # A paced simulator stops at this microsecond: a wait for a time
            # on the grid (on_us_grid) sees it reached once it has stopped.
            _CLOCK_US.pack_into(self._clock_map, 8, max(0, math.ceil(until_s * 1e6 - 1e-3)) | flags)

    def state(self, servo_id: int) -> dict:
        """The models' state of one servo: angle (deg), velocity, current,
        winding temperature, supply, status, collisions, ..."""
        return _fields(self.control(f"state {servo_id}"))


def on_us_grid(t: float) -> float:
    """t rounded up to a whole microsecond, as the clock file counts: a
    paced simulator stops at the bound run_ahead_to writes for it, and the
    clock read there (its microseconds / 1e6) equals it, so a host that
    waits until the clock reaches t goes on only once the simulator has
    stopped there, not while it is still on its way (a race that made a
    paced run differ by the host's speed)."""
    return math.ceil(t * 1e6 - 1e-3) / 1e6


def _stop(process) -> str:
    """Stops a child process; returns what it wrote to stderr."""
    if process is None:
        return ""
    process.terminate()
    try:
        _, err = process.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
    return err
