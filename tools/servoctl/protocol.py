"""The bus: sends requests and waits for the matching response, on a serial
port or a simulator's socket. The frames themselves are codec.py's, named
here too (p.request_frame, p.PING and the like)."""
import math
import time

from . import codec as _codec
from .codec import (ANSWER_FRAME_MAX, BROADCAST, BUS_IN_USE, CODES, MAX_ID, REPEATABLE,  # noqa: F401
                    REQUEST_HEADER, RESPONSE_HEADER, _frame_size, answer_frame_size, checksum,
                    decode_answer, encode_request, field_range, request_format, request_frame,
                    response_frame)
# The errors are errors.py's; named here too, as p.NoReply and the like.
from .errors import (BadAnswer, BadChecksum, LinkError, NoReply, Refused,  # noqa: F401
                     ServoError, UsageError, ValueOutOfRange)

globals().update(_codec.CODES)  # protocol.PING, protocol.WRITE_DATA, ...


try:  # a pty whose other end is gone fails in termios, which is not an OSError
    import termios

    _TERMIOS_ERRORS = (termios.error,)
except ImportError:  # not on Windows
    _TERMIOS_ERRORS = ()


# Host seconds a socket may take no bytes of a write before the link is
# taken for dead (a simulator on a loaded PC takes them within a second).
WRITE_STALL_S = 10.0
# The most simulated seconds a simulator runs ahead of the bus's last look at
# its clock while the bus waits for an answer (Bus.run_ahead).
RUN_AHEAD_S = 0.02


# The URL schemes pyserial opens; socket:// and rfc2217:// need HOST:PORT.
_SCHEMES = ("socket", "rfc2217", "loop", "spy", "hwgrep", "alt", "cp2110")
PORT_FORMS = ("a serial device (/dev/ttyUSB0, /dev/serial/by-id/..., COM3) or socket://HOST:PORT "
              "(a simulator's bus, as `servoctl sim` prints it: socket://127.0.0.1:5000)")


def check_port(port: str) -> None:
    """A port servoctl can open, by its form: UsageError naming the forms
    taken otherwise (pyserial's own words were "'<=' not supported between
    instances of 'int' and 'NoneType'"). Whether it is there is the
    opening's to say."""
    scheme, sep, rest = str(port).partition("://")
    if not sep:
        if not str(port).strip():
            raise UsageError(f"--port is empty: give {PORT_FORMS}")
        return
    if scheme.lower() not in _SCHEMES:
        raise UsageError(f"--port {port!r}: no such kind of port ({scheme}://): give {PORT_FORMS}")
    if scheme.lower() in ("socket", "rfc2217"):
        host, colon, number = rest.split("?", 1)[0].split("/", 1)[0].rpartition(":")
        if not colon or not host or not number.isdigit() or not 1 <= int(number) <= 65535:
            raise UsageError(f"--port {port!r} is not {scheme}://HOST:PORT with a port of 1-65535: give "
                             f"{PORT_FORMS}")


class Bus:
    """A serial port (or pyserial URL such as socket://127.0.0.1:5000) with
    the request/response discipline of the protocol.

    Every wait (reply timeouts, Bus.sleep, servoctl's waits for a move) is
    measured on `clock`, seconds: the host's monotonic clock for a real
    bus; for the simulator its own clock (Simulator.clock_s), which falls
    behind the wall clock on a busy PC while the servos keep their timing."""

    def __init__(self, port: str, baud: int = 115200, timeout: float = 0.1, clock=None, run_ahead=None):
        import serial  # pyserial

        self.timeout = timeout
        self.clock = clock or time.monotonic
        # A simulator whose clock may run ahead while this host waits on it
        # (Simulator.run_ahead_to): told each time the bus looks at the
        # clock; unless given, the clock's own simulator's (servoctl's
        # commands run with clock=sim.clock_s).
        self.run_ahead = run_ahead or getattr(getattr(clock, "__self__", None), "bus_run_ahead", None)
        # A paced simulator is told the bytes sent, so it takes them when
        # they were sent (Simulator.bus_sent).
        self.note_sent = getattr(getattr(clock, "__self__", None), "bus_sent", None)
        self.note_read = getattr(getattr(clock, "__self__", None), "bus_read", None)  # and those read
        self.port = port
        check_port(port)
        try:
            # Exclusive: a second program on the port would take answers
            # meant for this one (a flock on a serial device; other URLs
            # ignore it).
            self.serial = serial.serial_for_url(port, baudrate=baud, timeout=0, exclusive=True)
        except serial.SerialException as e:
            if "exclusively lock" in str(e):
                raise LinkError(f"{port} is in use by another program (another servoctl, a "
                                f"terminal, the maker's tool): close it, then try again") from None
            raise LinkError(f"cannot open {port}: {e}") from None
        except (ValueError, OSError, *_TERMIOS_ERRORS) as e:
            raise LinkError(f"cannot open {port}: {e}") from None
        sock = getattr(self.serial, "_socket", None)
        if sock is not None:  # socket://: no Nagle delay on small frames
            import socket

            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        # Reads never block (timeout 0); a wait for bytes is a select on
        # the port, which returns the moment one arrives.
        self._fd = sock.fileno() if sock is not None else getattr(self.serial, "fd", None)
        # A socket (non-blocking, as pyserial opens it) is read and written
        # directly: pyserial's wrappers add a select to every call, and a
        # robot's loop makes a call for each frame.
        self._sock = sock
        self._low_water = 1  # the socket's SO_RCVLOWAT (_wake_at)
        self._buffer = b""
        self.stray_bytes = 0  # bytes outside any frame: noise, or answers that collided
        self.bad_frames = 0  # frames with a bad checksum: noise, or answers that collided
        self.heard = False  # a whole frame came: the host and the line agree on the rate
        self.sent_again = 0  # requests sent a second time, their first unanswered (request)
        self.stamp_arrivals = True
        # The bus clock when the last response returned was taken off the
        # port: when the answer arrived, not when it was used.
        self.arrived_at = 0.0

    def close(self):
        try:
            self.serial.close()
        except (OSError, *_TERMIOS_ERRORS):
            pass  # a link already gone has nothing left to close

    def sleep(self, seconds: float) -> None:
        """Waits until the bus's clock has moved on by seconds."""
        if self.clock is time.monotonic:
            time.sleep(seconds)
            return
        end = self.clock() + seconds
        if self.run_ahead is not None:
            end = _on_us_grid(end)
            self.run_ahead(end)
        while (left := end - self.clock()) > 0:
            time.sleep(min(left, 0.005))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _link(self, what, *args):
        """pyserial's own exceptions stay inside: a dropped link is a
        LinkError with the port's name."""
        import serial

        try:
            return what(*args)
        except (serial.SerialException, OSError, *_TERMIOS_ERRORS) as e:
            raise LinkError(f"{self.port}: the link failed: {e}") from None

    def send(self, code: int, content: bytes) -> None:
        self.send_burst([(code, content)])

    def send_burst(self, requests) -> None:
        """Requests (code, content) back to back in one write, so they reach
        the line as one burst, without the gap a host may leave between two
        writes."""
        # What waits unread is dropped, as reset_input_buffer would, but
        # looked at first: it may say the bus is not ours. (Bounded: a line
        # that never stops talking is not waited out.)
        for _ in range(64):
            if not self._fill(wait=False):
                break
        self._buffer = b""
        frames = b"".join(request_frame(c, content) for c, content in requests)
        self._link(self.serial.write if self._sock is None else self._write_all, frames)
        if self.note_sent is not None:
            self.note_sent(len(frames))

    def _fill(self, wait: bool = True) -> bool:
        """Reads what has arrived; with wait, first waits up to 5 ms for a
        byte, returning as soon as one is there, so an answer is taken the
        moment its last byte is. True if anything came."""
        if wait:
            if self._fd is not None:
                import select

                if self._sock is not None:
                    self._wake_at(self._bytes_missing())
                select.select([self._fd], [], [], 0.005 if self.run_ahead is None else 0.001)
            else:  # loop:// and other ports without a descriptor
                time.sleep(0.0005)
        data = self._link(self._read_now)
        if BUS_IN_USE in data:
            raise LinkError(f"{self.port} is in use by another program (another servoctl, a "
                            f"terminal, the maker's tool): close it, then try again")
        self._buffer += data
        if data and self.note_read is not None:
            self.note_read(len(data))
        return bool(data)

    def _bytes_missing(self) -> int:
        """The fewest bytes that can complete the frame the buffer starts
        (_take_frame has left it at a header, or empty)."""
        buf = self._buffer
        if len(buf) >= 4:
            return max(1, _frame_size(buf) - len(buf))
        return 5 - len(buf)  # header, code, length, checksum

    def _wake_at(self, count: int) -> None:
        """The socket reads as ready once count bytes are there: the host
        wakes once a frame, not for each byte a simulator delivers as it
        ends on the wire (and takes its CPU meanwhile). A read takes what
        has come whatever the mark, and every wait is 5 ms at most."""
        if count != self._low_water:
            import socket

            self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVLOWAT, count)
            self._low_water = count

    def _read_now(self) -> bytes:
        """What has arrived, without waiting."""
        if self._sock is None:
            return self.serial.read(4096)
        try:
            data = self._sock.recv(4096)
        except (BlockingIOError, InterruptedError):
            return b""
        if not data:
            raise OSError("the other end closed the connection")
        return data

    def _write_all(self, data: bytes) -> None:
        """data to the socket; a simulator whose line is still busy with
        earlier bytes reads no more until it has room: waited for, up to
        WRITE_STALL_S of host time without a byte taken."""
        import select

        view = memoryview(data)
        stalled_at = None
        while view:
            try:
                view = view[self._sock.send(view):]
                stalled_at = None
            except (BlockingIOError, InterruptedError):
                stalled_at = stalled_at or time.monotonic()
                if time.monotonic() - stalled_at > WRITE_STALL_S:
                    raise OSError(f"nothing was taken for {WRITE_STALL_S:g} s") from None
                select.select([], [self._sock], [], 0.1)

    def read_response(self, code: int, servo_id, timeout=None, deadline=None, item=None):
        """Content of the next response with this packet number from this
        servo (any servo if servo_id is None), about item where given (a
        ReadData's: a late answer to an earlier read of another item is
        not this one's); other frames on the wire are skipped. It must come within timeout (the bus's if None), or by
        deadline on the bus clock. The bus clock is read as little as it
        can be (a virtual board's is a request to it): at the start, when
        the line is idle, every 2 ms of a stream of other bytes, and to
        stamp the answer's arrival (arrived_at) if stamp_arrivals."""
        wait = self.timeout if timeout is None else timeout
        if deadline is None:
            deadline = self.clock() + wait
        if self.run_ahead is not None:
            self._look(deadline)
        want = b"" if servo_id is None else bytes([servo_id] + ([] if item is None else [item]))
        bad = None
        last_look = False
        got = True  # the deadline was just read
        check_at = time.monotonic() + 0.002
        while True:
            frame = self._take_frame()
            if frame is not None:
                fcode, content, ok = frame
                if not ok:
                    bad = fcode
                    self.bad_frames += 1
                elif fcode == code and content[:len(want)] == want[:max(1, len(content))]:  # short: told
                    self.arrived_at = self.clock() if self.stamp_arrivals else None
                    self._look(0.0)  # the answer came: the simulator waits for the host's next bytes
                    return content
                continue
            # A host that was not scheduled until after the deadline reads
            # what arrived meanwhile once more before it gives up.
            if last_look:
                who = "no servo" if servo_id is None else f"servo {servo_id}"
                if bad is not None:
                    raise BadChecksum(f"{who}: response to packet {code} had a bad checksum")
                raise NoReply(f"{who}: no reply to packet {code} within {wait * 1000:.0f} ms")
            if not got or time.monotonic() >= check_at:
                if self.note_read is not None:
                    self.note_read(0, waits_for_more=True)  # every byte read looked at: none is it
                last_look = self._look(deadline)
                check_at = time.monotonic() + 0.002
            got = self._fill(wait=not last_look)

    def gather(self, code: int, content: bytes, window_s: float) -> tuple:
        """Sends a request and keeps listening window_s after it: two servos
        on one ID both answer. (contents of the good answers from that
        servo, frames with a bad checksum, bytes outside any frame)."""
        self.send(code, content)
        self.stray_bytes = 0
        good, bad = [], 0
        deadline = self.clock() + window_s
        if self.run_ahead is not None:
            self._look(deadline)
        last_look = finishing = False
        while True:
            while (frame := self._take_frame()) is not None:
                fcode, answer, ok = frame
                if not ok:
                    bad += 1
                elif fcode == code and answer[:1] == content[:1]:
                    good.append(answer)
            if last_look:
                self._look(0.0)
                return good, bad, self.stray_bytes + len(self._buffer)
            last_look = self._look(deadline)
            if last_look and self._buffer and not finishing:
                # A frame begun in the window is read whole, not counted as
                # garbage: the longest answer's time more, and 5 ms.
                finishing, last_look = True, False
                deadline = self.clock() + self._longest_answer_s()
            self._fill(wait=not last_look)

    def _look(self, deadline: float) -> bool:
        """Whether the bus clock has passed deadline. A simulator that runs
        ahead while the host waits may run to just past it, at most
        RUN_AHEAD_S past now (deadline 0: no more). A paced one (note_sent)
        to just past it: it stops at the answer itself, and a bound taken
        from the clock as the host happens to read it would make its stops
        the host's. Its wait ends there, not at an event on the way that a
        host read first (a loaded PC): the next request lands on time."""
        now = self.clock()
        if self.run_ahead is None:
            return now > deadline
        if self.note_sent is None:
            self.run_ahead(min(deadline + 0.001, now + RUN_AHEAD_S), answer=True)
            return now > deadline
        stop = _on_us_grid(deadline + 0.001)
        self.run_ahead(stop, answer=True)
        return now >= stop

    def _take_frame(self):
        """(code, content, checksum_ok) of a complete response frame at the
        head of the buffer, or None; garbage before a header is dropped."""
        buf = self._buffer
        start = buf.find(RESPONSE_HEADER)
        if start < 0:
            keep = buf[-1:] if buf[-1:] == RESPONSE_HEADER[:1] else b""
            self.stray_bytes += len(buf) - len(keep)
            self._buffer = keep
            return None
        self.stray_bytes += start
        buf = buf[start:]
        self._buffer = buf
        if len(buf) < 5:
            return None
        end = _frame_size(buf)
        if len(buf) < end:
            return None
        self._buffer = buf[end:]
        frame = buf[:end]
        self.heard |= checksum(frame[:-1]) == frame[-1]
        return frame[2], frame[4:-1], checksum(frame[:-1]) == frame[-1]

    def request(self, code: int, content: bytes, timeout=None, again=None) -> bytes:
        """Sends a request for the servo named by content[0] and returns its
        answer's content. Unanswered, it is sent once more if again (by
        default, if it only reads: REPEATABLE): it may have landed in a page
        erase, carried out but not answered."""
        item = {"item": content[1]} if code == READ_DATA else {}
        self.send(code, content)
        try:
            return self.read_response(code, content[0], timeout, **item)
        except NoReply:
            if not (code in REPEATABLE if again is None else again):
                raise
        self.sent_again += 1
        self.drain()
        self.send(code, content)
        return self.read_response(code, content[0], timeout, **item)

    def _longest_answer_s(self) -> float:
        return ANSWER_FRAME_MAX * 10 / self.serial.baudrate + 0.005

    def drain(self) -> None:
        """Waits out an answer still on its way (the longest's time on the
        wire and 5 ms, on the bus clock) and drops it: after a NoReply, a
        late answer is not taken for the next request's."""
        deadline = self.clock() + self._longest_answer_s()
        stop = _on_us_grid(deadline + 0.001)
        if self.run_ahead is not None:
            self.run_ahead(stop)
        paced = self.run_ahead is not None and self.note_sent is not None  # it stops there (_look)
        while self.clock() < stop if paced else self.clock() <= deadline:
            self._fill(wait=True)
        while (frame := self._take_frame()) is not None:  # garbled answers counted
            self.bad_frames += not frame[2]
        self.stray_bytes += len(self._buffer)
        self._buffer = b""


def _on_us_grid(t: float) -> float:
    """t rounded up to a whole microsecond (sim.on_us_grid): where a paced
    simulator told to run to t stops, and the clock it then shows."""
    return math.ceil(t * 1e6 - 1e-3) / 1e6
