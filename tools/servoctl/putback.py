"""Stored items a command writes along the way (calibrate's binary search
of item 91, the direction it tries on item 82, tune's drive and gain items
before their check), put back as they were when the command does not
finish: Ctrl-C, the ui's STOP ALL or its tab closing, an error, a servo
that stops answering. Each item is in flash: a search's midpoint left there
(a current_zero of 2047) makes the servo read 0 A while it draws current,
and every current protection is blind from then on, after a power-up too.

    with PutBack(servo, "calibrate") as kept:
        kept.write("current_zero", mid)     # the old value read first
    # an exception inside: every item written is put back, then it goes on

The put-back itself goes on through the ui's interrupt (a bus that an
interrupt ends between steps gives `finishing`, ui/preempt.py): it only
writes what the servo held before, and drives nothing. A Ctrl-C during it
waits for its end. Where it fails, NotPutBack (exit 5) names each item,
the value it holds and the value it should hold."""
import contextlib
import signal
import sys
import threading

from . import registers, stability, units
from .errors import NotPutBack, ServoError


class PutBack:
    def __init__(self, servo, command: str):
        self.servo, self.command = servo, command
        self.old = {}   # name: the value before the command's first write of it
        self.last = {}  # name: the last value the command wrote (or tried to)

    def _remember(self, names) -> None:
        for name in names:
            if name not in self.old:
                self.old[name] = self.servo.read(name)

    def write(self, name: str, value: int) -> None:
        self._remember([name])
        self.last[name] = value  # before it is sent: one cut off may have landed
        self.servo.write(name, value)

    def write_drive(self, values: dict) -> None:
        """Drive and gain items (80-88) as Servo.write_drive writes them."""
        self._remember(values)
        self.last.update(values)
        self.servo.write_drive(values)

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is None or not self.old:
            return False
        why = _why(exc)
        with _finishing(self.servo.bus), _ctrl_c_waits():
            failed = self._put_back()
        if failed:
            raise NotPutBack(self._said(why, failed)) from exc
        names = ", ".join(f"{n} ({registers.find(n).id}) {self._shown(n, self.old[n])}" for n in self.old)
        print(f"servoctl: {self.command} stopped part-way ({why}): put back as they were: {names}",
              file=sys.stderr, flush=True)
        return False

    def _put_back(self) -> dict:
        """{name: why} of each item not put back."""
        failed = {}
        drive = {n: v for n, v in self.old.items() if n in stability.ITEMS}
        others = {n: v for n, v in self.old.items() if n not in stability.ITEMS}
        for name, value in others.items():
            try:
                self.servo.write(name, value)
            except (ServoError, OSError) as e:  # the next items still put back
                failed[name] = str(e)
        if drive:
            try:  # in an order in which each set along the way keeps the loop stable
                self.servo.write_drive(drive)
            except (ServoError, OSError) as e:
                failed.update({name: str(e) for name in drive})
        return failed

    def _shown(self, name: str, value) -> str:
        item = registers.find(name)
        return units.show(item, value) if item.quantity else str(value)

    def _said(self, why: str, failed: dict) -> str:
        sid = self.servo.id
        each = "; ".join(
            f"{n} (item {registers.find(n).id}) holds {self._shown(n, self.last.get(n, self.old[n]))} "
            f"(the last value {self.command} wrote), it should hold {self._shown(n, self.old[n])} "
            f"(its value before {self.command}): {failed[n]}" for n in failed)
        fix = "; ".join(f"servoctl config set {sid} {n} {self.old[n]}" for n in failed)
        return (f"servo {sid}: {self.command} stopped part-way ({why}) and could NOT put back what it "
                f"had written: {each}. Until it is put back, do not drive the servo; put it back with: {fix}")


def _why(exc) -> str:
    if isinstance(exc, KeyboardInterrupt):
        return f"interrupted by {exc.args[0]}" if exc.args else "interrupted"
    return str(exc) or type(exc).__name__


def _finishing(bus):
    """The bus's own (the ui's: its interrupt does not cut the put-back), else none."""
    finishing = getattr(bus, "finishing", None)
    return finishing() if finishing is not None else contextlib.nullcontext()


@contextlib.contextmanager
def _ctrl_c_waits():
    """A Ctrl-C (or a SIGTERM, SIGHUP) during the put-back waits for its end
    (it is being interrupted already); on the main thread only, where
    Python takes it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {}
    try:
        for name in ("SIGINT", "SIGTERM", "SIGHUP"):
            number = getattr(signal, name, None)
            if number is not None:
                before[number] = signal.signal(number, lambda *a: None)
    except (ValueError, TypeError):  # not a handler Python may replace here
        pass
    try:
        yield
    finally:
        for number, handler in before.items():
            signal.signal(number, handler)


@contextlib.contextmanager
def signals_interrupt(names=("SIGTERM", "SIGHUP")):
    """SIGTERM and SIGHUP (a kill, a closed terminal) raise KeyboardInterrupt
    as Ctrl-C does, so that PutBack puts back what a command wrote before
    the process ends; the previous handlers are put back after. On the main
    thread only, where Python takes signals."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {}

    def interrupt(number, _frame):
        raise KeyboardInterrupt(signal.Signals(number).name)
    try:
        for name in names:
            number = getattr(signal, name, None)
            if number is not None:  # Windows has no SIGHUP
                before[number] = signal.signal(number, interrupt)
        yield
    finally:
        for number, handler in before.items():
            signal.signal(number, handler)
