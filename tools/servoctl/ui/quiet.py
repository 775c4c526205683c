"""What `servoctl ui`'s server says on stderr of its own (aiohttp's,
asyncio's and its own logs): one line a second at most, no tracebacks, and never
written by the server's thread. aiohttp logged a 10-line traceback for each
malformed request (no Host header, a bad Content-Length, a path over 8190
characters), written on the event loop: 2 865 such requests printed 20 620
lines, and with stderr a pipe nobody read, the loop blocked in its write and
STOP ALL never reached the wire.

Here the loop only puts one short line on a bounded queue (dropped, and
counted, when it is full); a thread of its own writes them to file
descriptor 2, the first of each second with how many more came."""
import logging
import os
import queue
import threading
import time

LOGGERS = ("aiohttp.server", "aiohttp.access", "aiohttp.web", "aiohttp.websocket",
           "aiohttp.internal", "asyncio", "servoctl.ui")
EVERY_S = 1.0    # host time: at most one line this often
QUEUE_MAX = 256  # lines waiting for the writer; more are dropped and counted
LINE_MAX = 200   # characters of one line


class Quiet(logging.Handler):
    """The loggers' handler: emit() formats one line (no traceback) and
    queues it, never waiting."""

    def __init__(self, fd: int = 2, every_s: float = EVERY_S):
        super().__init__(logging.WARNING)
        self.fd, self.every_s = fd, every_s
        self.lines = queue.Queue(QUEUE_MAX)
        self.dropped = 0
        self.thread = threading.Thread(target=self._write, name="servoctl-ui-log", daemon=True)
        self.thread.start()

    def emit(self, record):
        try:
            line = record.getMessage()
            if record.exc_info and record.exc_info[1] is not None:
                e = record.exc_info[1]
                line += f": {type(e).__name__}: {' '.join(str(e)[:LINE_MAX * 2].split())}"
            line = "".join(c if c.isprintable() else "?" for c in line[:LINE_MAX])
            self.lines.put_nowait(line)
        except queue.Full:
            self.dropped += 1  # the loop's thread alone counts up; the writer only reads
        except Exception:  # noqa: BLE001 - a log line never takes the server down
            self.dropped += 1

    def close(self):
        """Says what is left, waiting a moment for the writer at most (a
        stderr nobody reads holds it, not the server)."""
        try:
            self.lines.put_nowait(None)
        except queue.Full:
            pass
        self.thread.join(timeout=0.5)
        super().close()

    def _write(self):
        first, more, last, seen_dropped = None, 0, 0.0, 0
        while True:
            try:
                line = self.lines.get(timeout=self.every_s)
            except queue.Empty:
                line = ""
            if line is not None and line:
                if first is None:
                    first = line
                else:
                    more += 1
            dropped, seen_dropped = self.dropped - seen_dropped, self.dropped
            more += dropped
            now = time.monotonic()
            if (first is not None or more) and (now - last >= self.every_s or line is None):
                text = f"servoctl ui: {first or 'the server logged'}" + (f" (and {more} more)" if more else "")
                try:
                    os.write(self.fd, (text + "\n").encode(errors="replace"))
                except OSError:
                    pass
                first, more, last = None, 0, now
            if line is None:
                return


def start() -> Quiet:
    """The handler of aiohttp's and asyncio's loggers from now on (none of
    their records reaches the root logger or logging's last resort)."""
    handler = Quiet()
    for name in LOGGERS:
        log = logging.getLogger(name)
        log.handlers = [handler]
        log.propagate = False
        if log.level == logging.NOTSET or log.level < logging.WARNING:
            log.setLevel(logging.WARNING)
    return handler
