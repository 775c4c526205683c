"""STOP ALL ahead of whatever the bus thread is doing (docs/ui.md, "STOP
ALL"). The broadcast stop is written the moment the page asks, by the
thread that hears the page (or by a stop thread of its own once the write
that holds the wire ends), so neither a wait for a silent servo's answer,
nor a sleep, nor a fit's CPU time, nor an import holds it back; the bus
thread's command ends at its next look at the port (every STEP_S at most,
waits included).

One lock orders the bus's writes: a command's write checks the interrupt
inside it, so nothing a command sends can follow the stop on the wire, but
for one thing: a command stopped part-way puts back the stored items it
had written (putback.py, through bus.finishing()): writes that drive
nothing, of what the servo held before."""
import contextlib
import queue
import threading
import time

from .. import link_rate, registers
from .. import protocol as p

STEP_S = 0.005  # the longest a bus wait or sleep goes without looking at the interrupt
STOP_METHOD = {"release": 0x10, "damping": 0x12}  # StopOnControlMode's, as Servo.stop's
WRITES = {"write", "_write_all"}  # what Bus._link is handed to write (a port, a socket)
AGAIN_S = 0.01  # host time: a click this soon after a broadcast adds nothing to the wire
# After a frame at one rate, before the next at another: the adapter's (or
# the simulator's) last byte out before the port changes rate.
RATE_SWITCH_S = 0.002


class Preemption:
    """Wraps one Bus: every read, write and sleep of it raises
    KeyboardInterrupt once interrupt() is called (servoctl's commands end
    on it as on Ctrl-C, the host's rate put back by scan's own finally)."""

    def __init__(self, bus):
        self.bus = bus
        self.wire = threading.Lock()
        self.flag = threading.Event()
        self.why = "stop-all"
        self._link, self._sleep = bus._link, bus.sleep
        bus._link, bus.sleep = self._link_unless_interrupted, self._sleep_unless_interrupted
        bus.finishing = self.finishing
        self._finishing = 0  # the bus thread's put-backs under way: not interrupted
        self._stops = queue.SimpleQueue()
        self._last_stop = 0.0  # time.monotonic() of the last broadcast written
        self.thread = threading.Thread(target=self._stop_thread, name="servoctl-ui-stop", daemon=True)
        self.thread.start()

    def interrupt(self, why: str) -> None:
        self.why = why
        self.flag.set()

    def clear(self) -> None:
        self.flag.clear()

    def check(self) -> None:
        if self.flag.is_set() and not self._finishing:
            raise KeyboardInterrupt(self.why)

    @contextlib.contextmanager
    def finishing(self):
        """On the bus thread: what runs inside (a put-back) is not cut by
        the interrupt; the next look at it after raises as before."""
        self._finishing += 1
        try:
            yield
        finally:
            self._finishing -= 1

    def broadcast_stop(self, mode: str) -> None:
        """A broadcast StopOnControlMode on the wire now (any thread may
        ask): written here if no write holds the wire (on a loaded PC a
        thread's wake-up costs milliseconds), else by the stop thread as
        soon as that write ends."""
        if self.wire.acquire(blocking=False):
            try:
                self._write_stop(mode)
            finally:
                self.wire.release()
        else:
            self._stops.put(mode)

    def close(self) -> None:
        self._stops.put(None)
        self.thread.join(timeout=2)

    # The wrapped bus -----------------------------------------------------

    def _link_unless_interrupted(self, what, *args):
        if getattr(what, "__name__", "") in WRITES:
            with self.wire:
                self.check()
                return self._link(what, *args)
        self.check()
        return self._link(what, *args)

    def _sleep_unless_interrupted(self, seconds: float) -> None:
        end = self.bus.clock() + seconds
        while (left := end - self.bus.clock()) > 0:
            self.check()
            self._sleep(min(left, STEP_S))
        self.check()

    def _stop_thread(self):
        while (mode := self._stops.get()) is not None:
            # Clicks that came meanwhile (a page gone wild): one broadcast for
            # them all, the last one's mode, not a wire full of stops.
            while not self._stops.empty() and mode is not None:
                mode = self._stops.get_nowait()
            if mode is None:
                return
            with self.wire:
                self._write_stop(mode)

    def _write_stop(self, mode: str) -> None:
        """The broadcast, the wire's lock held; one for a burst of clicks."""
        if time.monotonic() - self._last_stop < AGAIN_S:
            return
        frame = p.request_frame(p.STOP_ON_CONTROL, p.encode_request(
            p.STOP_ON_CONTROL, p.BROADCAST, STOP_METHOD[mode], 0))
        # Written as Bus.send writes, without its look at what came in:
        # the bus thread owns the reading.
        write = self.bus.serial.write if self.bus._sock is None else self.bus._write_all
        try:
            self._link(write, frame)
            if self.bus.note_sent is not None:
                self.bus.note_sent(len(frame))
            self._last_stop = time.monotonic()
        except Exception:  # noqa: BLE001 - a lost link: the bus thread's stop_all reports it
            pass


def stop_at_every_rate(bus, sim_control, mode: str) -> list:
    """On the bus thread, after the broadcast at the host's rate: the
    broadcast again at every other rate item 36 gives a servo, then the
    host's rate back, so a servo set to another rate (from the page: the
    host's rate follows the one changed, the others stay at the old) is
    stopped too. Fastest first; before each change of rate the port is
    drained and the frame's wire time waited. Open loop: no servo answers
    a broadcast. A rate the port refuses, or a failed return to the host's
    rate, is a line of what failed, never an end to STOP ALL: the servos'
    own stops follow whatever happened here. None where it cannot sweep
    (socket:// without the simulator's control port: the far end sets the
    rate)."""
    if link_rate.is_socket(bus.port) and not sim_control:
        return None
    host = bus.serial.baudrate
    content = p.encode_request(p.STOP_ON_CONTROL, p.BROADCAST, STOP_METHOD[mode], 0)
    wire_bits = len(p.request_frame(p.STOP_ON_CONTROL, content)) * 10
    failed = []
    for rate in [*sorted(set(registers.BAUD_RATES.values()) - {host}, reverse=True), host]:
        try:
            _drained(bus)
            link_rate.set_rate(bus, sim_control, rate)
            if rate != host:
                bus.send(p.STOP_ON_CONTROL, content)
                _drained(bus)
                bus.sleep(wire_bits / rate + RATE_SWITCH_S)
        except KeyboardInterrupt:
            _back_to(bus, sim_control, host, failed)
            raise  # another STOP ALL: it sweeps again
        except Exception as e:  # noqa: BLE001 - a port that refuses a rate (SerialException, OSError)
            failed.append(f"broadcast stop at {rate} baud: {e}" if rate != host
                          else f"the host's rate back to {host} baud: {e}")
    if bus.serial.baudrate != host:
        _back_to(bus, sim_control, host, failed)
    return failed


def _drained(bus) -> None:
    """What the port holds written out (tcdrain on a serial port)."""
    flush = getattr(bus.serial, "flush", None)
    if flush is not None and bus._sock is None:
        flush()


def _back_to(bus, sim_control, host: int, failed: list) -> None:
    try:
        link_rate.set_rate(bus, sim_control, host)
    except Exception as e:  # noqa: BLE001 - said; the servos' own stops follow
        failed.append(f"the host's rate back to {host} baud: {e}; it is at {bus.serial.baudrate}")
