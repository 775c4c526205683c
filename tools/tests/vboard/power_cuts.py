"""A virtual board in this process, driven as servoctl drives a servo, with
its flash put back to a saved image between runs: so a test runs one flash
sequence again and again, the power cut at each of its operations in turn
(the flash model's cut_after_ops, the control port's cutflash), without a
process or a set-up each time. Time is the board's simulated time."""
from types import SimpleNamespace

from servoctl import protocol as p
from servoctl.codec import RESPONSE_HEADER, _frame_size, checksum
from servoctl.protocol import NoReply
from vboard import bench


class Host:
    """What servoctl's Servo and update ask of a bus (request, clock, sleep,
    drain, the baud rate), on the runner's bus with no socket between."""

    def __init__(self, runner, timeout: float = 0.1):
        self.runner, self.timeout = runner, timeout
        self.serial = SimpleNamespace(baudrate=115200)
        self.sent_again = 0
        self.answered = []  # the codes answered since the last look (a cut's test reads it)

    def clock(self) -> float:
        return self.runner.now_s

    def run(self, until_s: float, done=lambda: False) -> bool:
        r = self.runner
        while r.now_s < until_s:
            r.step(until_s)
            r.bus.flush_to_host(r.now_s)
            if done():
                return True
        return done()

    def sleep(self, seconds: float) -> None:
        self.run(self.runner.now_s + seconds)

    def send(self, code: int, content: bytes) -> None:
        self.runner.bus.to_host.clear()
        for byte in p.request_frame(code, content):
            self.runner.bus.queue_host(byte, self.runner.now_s)

    def _frame(self, code: int, servo_id: int):
        buf = self.runner.bus.to_host
        start = buf.find(RESPONSE_HEADER)
        if start < 0 or len(buf) < start + 5 or len(buf) < start + _frame_size(bytes(buf[start:])):
            return None
        end = start + _frame_size(bytes(buf[start:]))
        frame = bytes(buf[start:end])
        del buf[:end]
        if checksum(frame[:-1]) == frame[-1] and frame[2] == code and frame[4] == servo_id:
            return frame[4:-1]
        return self._frame(code, servo_id)

    def request(self, code: int, content: bytes, timeout=None, again=None) -> bytes:
        self.send(code, content)
        got = []
        self.run(self.runner.now_s + (timeout or self.timeout),
                 lambda: got.append(self._frame(code, content[0])) or got[-1] is not None)
        if got and got[-1] is not None:
            self.answered.append(code)
            return got[-1]
        raise NoReply(f"servo {content[0]}: no reply to packet {code}")

    def drain(self) -> None:
        self.sleep(0.01)
        self.runner.bus.to_host.clear()


def cut_points(kinds: list, every: int) -> list:
    """Where to cut (1 the first operation): all of them (every 1), else
    each erase, the first two and last two program steps and every
    every-th: a record's steps on the F1/F0 are half-words, alike but for
    which lands last."""
    n = len(kinds)
    return sorted({k for k in range(1, n + 1)
                   if every == 1 or kinds[k - 1] or k <= 2 or k >= n - 1 or k % every == 0})


class Cuts:
    """One board: its flash saved (put), and put back with a power-up."""

    def __init__(self, board: str, state_dir: str):
        self.runner = bench.runner_for(board, [1], state_dir)
        self.board = self.runner.boards[0]
        self.flash = self.board.flash
        self.host = Host(self.runner)

    def close(self) -> None:
        self.runner.bus.close()
        self.runner.control.close()
        self.runner.clock.close()

    def save(self):
        return bytes(self.board.flash_mem.read(0, self.board.flash_size)), set(getattr(self.flash, "torn", ()))

    def put_back(self, image) -> None:
        """The flash as saved, then a power-up (off 0.1 s, RAM lost)."""
        data, torn = image
        self.board.flash_mem.write(0, data)
        self.flash.persist(0, len(data))
        if hasattr(self.flash, "torn"):
            self.flash._mend(0, len(data))
            for offset in torn:
                self.flash._tear(offset)
        self.flash.cut_after_ops = 0
        self.board.power_cycle()

    def write_flash(self, address: int, data: bytes) -> None:
        """Bytes straight into the flash image (a state set up, not programmed)."""
        self.board.flash_mem.write(address - self.board.flash_base, data)

    def boots(self, seconds: float = 1.0) -> bool:
        """The board answers a Ping (its bootloader or its application)
        within seconds of simulated time."""
        end = self.runner.now_s + seconds
        while self.runner.now_s < end:
            try:
                self.host.request(p.PING, bytes([1]), timeout=0.02)
                return True
            except NoReply:
                pass
        return False

    def in_application(self, seconds: float = 1.0) -> bool:
        """Its application runs and answers, within seconds."""
        return self.host.run(self.runner.now_s + seconds, self.board.in_application) and self.boots(seconds)

    def count(self, sequence) -> list:
        """The flash operations sequence() makes, in order: True for an
        erase, False for a program step."""
        kinds, cut = [], self.flash.cut
        self.flash.cut = lambda program: kinds.append(not program) or cut(program)
        try:
            sequence()
        finally:
            del self.flash.cut
        return kinds

    def cut_at(self, n: int, sequence) -> bool:
        """sequence() with the power cut as its nth flash operation begins;
        True if it was (the board then starts again on its own)."""
        resets = self.board.resets["power"]
        self.flash.cut_after_ops = n
        sequence()
        self.flash.cut_after_ops = 0
        return self.board.resets["power"] > resets
