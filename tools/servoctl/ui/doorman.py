"""Who may hold a connection to `servoctl ui`'s server: one that has not
yet brought a request with the token is closed after FIRST_REQUEST_S (a
half-open connection, a request sent a byte a minute), and at most
UNTRUSTED_MAX such are open at once, one closed for a new one: the oldest
that has sent nothing for SILENT_S since it opened, else the oldest (a page
load whose request is under way is not reset by a flood of idle
connections, and a browser's new connection, silent for the moment its
request takes to come, is not the first closed by a flood that sends a
byte on each of its own).
Without it, thousands of idle connections took every file descriptor the
process may open and page loads timed out.

It stands between asyncio's server and aiohttp's protocol (a protocol
factory, asyncio's public interface); the token check (server.py) tells it
which connections brought the token."""
import asyncio
import collections

FIRST_REQUEST_S = 10.0  # host time: a browser sends its request at once
SILENT_S = 0.5          # host time: silent for longer, a connection is closed first
UNTRUSTED_MAX = 128     # a browser opens 6 connections to a host at most; 1024 files a process


class Doorman:
    def __init__(self, protocol_factory, first_request_s: float = FIRST_REQUEST_S,
                 untrusted_max: int = UNTRUSTED_MAX, silent_s: float = SILENT_S):
        self.factory = protocol_factory
        self.first_request_s, self.untrusted_max, self.silent_s = first_request_s, untrusted_max, silent_s
        self.untrusted = collections.OrderedDict()  # transport: its timer, oldest first
        self.silent = collections.OrderedDict()     # those of them that sent nothing yet: when they opened

    def __call__(self) -> asyncio.Protocol:
        return _Watched(self.factory(), self)

    def admit(self, transport) -> None:
        loop = asyncio.get_running_loop()
        now = loop.time()
        while len(self.untrusted) >= self.untrusted_max:  # room for this one
            idle = next(iter(self.silent.items()), None)  # the oldest silent one
            self._close(idle[0] if idle is not None and now - idle[1] >= self.silent_s
                        else next(iter(self.untrusted)))
        self.untrusted[transport] = loop.call_later(self.first_request_s, self._close, transport)
        self.silent[transport] = now

    def heard(self, transport) -> None:
        """Bytes came on it: a request under way, closed last."""
        self.silent.pop(transport, None)

    def trust(self, transport) -> None:
        """A request with the token came on it: aiohttp's keep-alive and
        the WebSocket's heartbeat time it out from now on."""
        self.silent.pop(transport, None)
        timer = self.untrusted.pop(transport, None)
        if timer is not None:
            timer.cancel()

    def forget(self, transport) -> None:
        self.trust(transport)

    def _close(self, transport) -> None:
        self.forget(transport)
        transport.abort()


class _Watched(asyncio.Protocol):
    """aiohttp's protocol for one connection, the doorman told when it
    opens and closes."""

    def __init__(self, inner, doorman: Doorman):
        self.inner, self.doorman, self.transport = inner, doorman, None

    def connection_made(self, transport):
        self.transport = transport
        self.doorman.admit(transport)
        self.inner.connection_made(transport)

    def connection_lost(self, exc):
        self.doorman.forget(self.transport)
        self.inner.connection_lost(exc)

    def data_received(self, data):
        self.doorman.heard(self.transport)
        self.inner.data_received(data)

    def eof_received(self):
        return self.inner.eof_received()

    def pause_writing(self):
        self.inner.pause_writing()

    def resume_writing(self):
        self.inner.resume_writing()
