"""What `servoctl ui`'s server tells one tab (its role, the broadcasts, the
answers to its requests), in order, written by a task of its own: no tab
waits for another to read. Before, the hello each opening tab sends every
tab waited, with no time limit, for a tab that had stopped reading once
aiohttp's writer had passed 256 KiB (it waits for the peer to drain there):
the new tab never reached its loop and its STOP ALL was never read; and the
server held every broadcast for such a tab without limit."""
import asyncio
import collections
import fcntl
import json
import logging
import struct
import termios

# What a tab has not read yet: its outbox, its transport's write buffer and
# the kernel's send queue (a stuck tab's takes megabytes on loopback). Over
# OUTBOX_MAX the tab is aborted (it stopped reading; a browser on this
# computer reads megabytes a second); over READING_MAX it is behind, and is
# not given the driving role (asyncio pauses writing at 64 KiB).
OUTBOX_MAX = 1024 * 1024
READING_MAX = 64 * 1024
LOG = logging.getLogger("servoctl.ui")  # through quiet.py: a line a second at most


class Outbox:
    """What one tab is told, in order, written by a task of its own: put()
    never waits, whether or not the tab reads. A tab that has not read
    OUTBOX_MAX bytes (its outbox, its socket's buffers) is aborted,
    not closed: a close would wait for the buffer it does not read."""

    def __init__(self, page, ws, transport, who: str):
        self.page, self.ws, self.transport, self.who = page, ws, transport, who
        self.texts = collections.deque()
        self.size = 0  # characters queued: bytes, json.dumps writes ASCII
        self.ready = asyncio.Event()
        self.cut = False
        self.task = asyncio.ensure_future(self._write())

    def unread(self) -> int:
        if self.transport is None:
            return self.size
        return self.size + self.transport.get_write_buffer_size() + _queued(self.transport)

    def reading(self) -> bool:
        return not self.cut and not self.ws.closed and self.unread() <= READING_MAX

    def put(self, text: str):
        if self.cut or self.ws.closed:
            return
        self.texts.append(text)
        self.size += len(text)
        self.ready.set()
        if self.unread() > OUTBOX_MAX:
            self.abort()

    def abort(self, why: str = None):
        """Cut off: for not reading, or why (a tab that floods, pace.py)."""
        unread = self.unread()
        self.cut = True
        self.texts.clear()
        self.size = 0
        if why is not None:
            LOG.warning("%s", why)
        else:
            LOG.warning("%s is cut off: %d bytes it was told are unread, over the %d a tab may leave unread",
                        self.who, unread, OUTBOX_MAX)
        if self.transport is not None:
            self.transport.abort()
        # Once the roles being told, if any, are: then it drives no more.
        asyncio.get_running_loop().call_soon(self.page._cut, self.ws)

    def close(self):
        self.cut = True
        self.texts.clear()
        self.size = 0
        self.task.cancel()

    async def _write(self):
        while not self.cut:
            if not self.texts:
                self.ready.clear()
                await self.ready.wait()
                continue
            text = self.texts.popleft()
            await send(self.ws, text)
            if self.cut:
                return
            self.size -= len(text)
            if self.page.driver is None and self.reading():  # caught up: it may drive
                self.page._elect()


def _queued(transport) -> int:
    """Bytes in the socket's kernel send queue, sent or not, that the peer
    has not taken (Linux's SIOCOUTQ); 0 where it cannot be asked."""
    sock = transport.get_extra_info("socket")
    try:
        return struct.unpack("i", fcntl.ioctl(sock.fileno(), termios.TIOCOUTQ, b"\0" * 4))[0]
    except (AttributeError, OSError, ValueError):
        return 0


async def send(ws, msg):
    """msg: a dict, or the text of one already serialised. Only a tab's
    own Outbox, or its own handler refusing it, awaits this."""
    if not ws.closed:
        try:
            await ws.send_str(msg if isinstance(msg, str) else json.dumps(msg))
        except (ConnectionError, RuntimeError):
            pass
