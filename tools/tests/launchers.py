"""The tests' launchers beyond servoctl's Simulator: the real ARM images on
QEMU (QemuBoard), a stand-in servo on a TCP port (FakeServo), and the
repository's files the tests start simulators with (PLANTS). Not shipped: servoctl finds a simulator as docs/simulator.md
says; the tests find the repository from here."""
import os
from pathlib import Path
import signal
import socket
import subprocess
import sys
import threading
import time

from servoctl.protocol import Bus, LinkError, ServoError
from servoctl.servo import Servo
from servoctl.sim import _Child

REPO = Path(__file__).resolve().parents[2]
PLANTS = REPO / "hal" / "ports" / "host" / "plants"  # the shipped plant files (--plant)
BOOT_TIMEOUT_S = 10


def _read(path: str) -> str:
    with open(path) as f:
        return f.read()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def servoctl_child(*argv, **popen) -> subprocess.Popen:
    """servoctl argv in a child process that Ctrl-C interrupts, as at a
    user's terminal, even where the tests run in the background: a shell
    starts a background job with SIGINT ignored, each process it starts
    inherits that, and Python then installs no KeyboardInterrupt handler,
    so the child would run on through the test's SIGINT. popen: Popen's."""
    return subprocess.Popen([sys.executable, "-m", "servoctl.cli", *argv], cwd=REPO / "tools", text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL), **popen)


QEMU_BOARD = REPO / "build" / "arm" / "firmware" / "boards" / "qemu_stm32vl"
QEMU_BOOTLOADER = QEMU_BOARD / "servo_qemu_stm32vl_boot.elf"
QEMU_IMAGE = QEMU_BOARD / "servo_qemu_stm32vl.img"
QEMU_SLOT = 0x08001000  # where the application's image goes (qemu_stm32vl/board.h)


class QemuBoard(_Child):
    """The real ARM images on QEMU's stm32vldiscovery: the bootloader at the
    start of flash, the application's update image in its slot; USART1 on a
    TCP port (pyserial socket://)."""

    def __init__(self, image=None, bootloader=None):
        self.image = Path(image or os.environ.get("SERVO_QEMU_IMAGE", QEMU_IMAGE))
        self.bootloader = Path(bootloader or QEMU_BOOTLOADER)
        self.process = None
        self.url = None
        self._vcpu = ""  # the vCPU thread's task id; "" for the whole process

    def cpu_s(self) -> float:
        """The CPU seconds QEMU's vCPU thread has had: the emulated board's
        progress (its firmware never sleeps, so the vCPU runs whenever the
        host lets it). QEMU's main loop thread spins too, so the whole
        process's time would run ahead of the guest by up to two. A Bus on
        this clock gives a starved QEMU the time it needs."""
        try:
            stat = _read(f"/proc/{self.process.pid}/task/{self._vcpu}/stat" if self._vcpu
                         else f"/proc/{self.process.pid}/stat")
        except OSError as e:
            raise LinkError(f"qemu is gone: {e.strerror}") from None
        fields = stat.rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def _find_vcpu(self) -> str:
        """The task id of QEMU's vCPU thread ("CPU 0/TCG"), which QEMU starts
        before it runs the guest; "" if none shows within 5 s."""
        task = f"/proc/{self.process.pid}/task"
        give_up = time.monotonic() + 5.0
        while time.monotonic() < give_up and self.process.poll() is None:
            try:
                for t in os.listdir(task):
                    if _read(f"{task}/{t}/comm").startswith("CPU "):
                        return t
            except OSError:
                pass
            time.sleep(0.01)
        return ""

    def bus(self, **kw) -> Bus:
        """A Bus to the board that waits on QEMU's progress (cpu_s)."""
        return Bus(self.url, clock=self.cpu_s, **kw)

    def start(self) -> "QemuBoard":
        for path in (self.image, self.bootloader):
            if not path.exists():
                raise ServoError(f"no image at {path}: build it with "
                                 f"'cmake --preset arm && cmake --build --preset arm'")
        port = _free_port()
        self.process = subprocess.Popen(
            ["qemu-system-arm", "-M", "stm32vldiscovery", "-kernel", str(self.bootloader),
             "-name", "servo,debug-threads=on",  # the vCPU thread by name: cpu_s
             "-device", f"loader,file={self.image},addr={QEMU_SLOT:#x}",
             "-nographic", "-monitor", "none",
             "-serial", f"tcp:127.0.0.1:{port},server=on,wait=off,nodelay=on"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.url = f"socket://127.0.0.1:{port}"
        self._vcpu = self._find_vcpu()
        # QEMU opens the port before the guest has booted, so the board is
        # ready only once the firmware answers: within BOOT_TIMEOUT_S of
        # QEMU's own CPU time, however long a loaded machine takes for it.
        bus = None
        hung_at = time.monotonic() + 30 * BOOT_TIMEOUT_S  # QEMU itself stuck
        try:
            while self.cpu_s() < BOOT_TIMEOUT_S and time.monotonic() < hung_at:
                if self.process.poll() is not None:
                    raise ServoError(f"qemu exited: {self.process.stderr.read().strip()}")
                try:
                    bus = bus or self.bus(timeout=0.2)
                except ServoError:  # the port is not open yet
                    time.sleep(0.05)
                    continue
                try:  # the application, not the bootloader, answers ReadData
                    Servo(bus, 0).read("serial")
                    return self
                except ServoError:
                    continue
        finally:
            if bus is not None:
                bus.close()
        self.stop()
        raise ServoError(f"the firmware on qemu did not answer within {BOOT_TIMEOUT_S} s of QEMU's CPU time")


class FakeServo:
    """A stand-in for servos on a TCP port (pyserial socket://, url): the
    subclass's _serve() answers, on a thread of its own, from the start."""

    def __init__(self, backlog: int = 1):
        self.server = socket.socket()
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(backlog)
        self.url = f"socket://127.0.0.1:{self.server.getsockname()[1]}"
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        raise NotImplementedError

    def close(self):
        self.server.close()
