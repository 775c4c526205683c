"""`servoctl ui`'s web server (aiohttp): the page, its assets and one
WebSocket, all behind the random token in the page's address. A request
without the token, or from a page of another origin (a web site asking the
local server to move the robot), is refused with 403. One tab drives the
bus; another is told which one does and only watches until that one
closes. Connections are let in by a doorman (doorman.py); every response
forbids framing; a malformed request is answered with an error and the tab
stays connected. What a tab is told goes through its own outbox (outbox.py):
no tab waits for another to read, and one that does not read is cut off."""
import asyncio
import datetime
import hmac
import ipaddress
import json
import os
import socket
from pathlib import Path

from aiohttp import WSMsgType, web
from yarl import URL

from . import quiet
from .doorman import Doorman
from . import fields
from .fields import Malformed
from .outbox import Outbox, send as _send
from .pace import Pace, is_stop
from .worker import QueueFull

STATIC = Path(__file__).parent / "static"
ASSETS = {p.name for p in STATIC.iterdir() if p.is_file()}
# No page of another site may frame this one (a click on its STOP or its
# move buttons through a transparent frame): both headers, for old browsers too.
NO_FRAMES = {"X-Frame-Options": "DENY", "Content-Security-Policy": "frame-ancestors 'none'"}
KEEPALIVE_S = 15  # an idle keep-alive connection with the token closes after this
# What a tab may send (docs/ui.md, "Malformed requests"): a request is a few
# hundred bytes; a longer one is refused by its length, before it is parsed.
# aiohttp reads up to READ_MAX (beyond it, it closes the connection with
# 1009), no compression: a small frame must not inflate to megabytes.
REQUEST_MAX = 64 * 1024
READ_MAX = 16 * 1024 * 1024
WATCHER_MAX = 1024  # a watching tab's request is STOP ALL's, a few dozen bytes
TABS_MAX = 8  # open tabs (WebSockets); one more is told so and closed
CLOSE_S = 1.0  # host seconds: a tab's close at shutdown, then it is aborted
ACCEPT_BATCH = 4  # connections the loop accepts a turn (asyncio's backlog argument)
LISTEN_QUEUE = 4096  # the kernel's queue of connections not yet accepted (Linux's somaxconn)


class Page:
    def __init__(self, worker, token: str, about: dict, hosts=None):
        self.worker, self.token, self.about = worker, token, about
        self.hosts = hosts  # the names the page may be asked by (DNS rebinding); None: any
        self.sockets = []   # every open tab's WebSocket, in order of opening
        self.driver = None  # the tab that drives the bus
        self.who = {}       # ws: how the other tabs are told of it
        self.outbox = {}    # ws: its Outbox
        self.loop = None
        self.doorman = None
        self.last_scan = None  # told to a tab that opens later: its Bus table has rows
        self.stop_mode = {}  # ws: its page's STOP ALL mode, used when it closes driving
        self.closing = False  # the ui stops (Ctrl-C): its tabs' close leaves the servos as they are

    # Safety -----------------------------------------------------------------

    def _refusal(self, request, need_origin: bool):
        given = request.query.get("token", "")
        if not hmac.compare_digest(given.encode(), self.token.encode()):
            return "refused: the address lacks this session's token (see servoctl ui's first line)"
        if self.hosts is not None:
            # Both the request line's host (an absolute-form request) and the Host header.
            try:
                line_host = request.url.host
            except ValueError:  # "Host: 127.0.0.1:abc": yarl cannot make a URL of it (was a 500)
                return "refused: a Host header that names no host and port"
            for host in (line_host, _header_host(request)):
                host = (host or "").strip("[]")
                if host not in self.hosts:
                    return f"refused: a request for host {host!r:.80}, not this computer's (DNS rebinding?)"
        origin = request.headers.get("Origin")
        own = _own_origins(request)
        if origin is None and need_origin:
            return "refused: a WebSocket without an Origin"
        if origin is not None and origin not in own:
            return f"refused: a request from another origin ({origin}), not {' or '.join(own)}"
        return None

    @web.middleware
    async def guard(self, request, handler):
        why = self._refusal(request, need_origin=request.path == "/ws")
        if why:
            return web.Response(status=403, text=why + "\n")
        if self.doorman is not None:
            self.doorman.trust(request.transport)
        return await handler(request)

    @staticmethod
    async def no_frames(request, response):
        response.headers.update(NO_FRAMES)

    # Routes -----------------------------------------------------------------

    async def index(self, request):
        html = (STATIC / "index.html").read_text().replace("{{TOKEN}}", self.token)
        return web.Response(text=html, content_type="text/html",
                            headers={"Cache-Control": "no-store", "Referrer-Policy": "no-referrer"})

    async def asset(self, request):
        name = request.match_info["name"]
        if name not in ASSETS or name == "index.html":
            raise web.HTTPNotFound()
        return web.FileResponse(STATIC / name)

    async def socket(self, request):
        ws = web.WebSocketResponse(heartbeat=20, compress=False, max_msg_size=READ_MAX)
        await ws.prepare(request)
        if len(self.sockets) >= TABS_MAX:
            try:  # this tab's own answer: at most CLOSE_S of its not reading
                await asyncio.wait_for(_send(ws, {"type": "error", "text": f"servoctl ui: {TABS_MAX} tabs are "
                                                  f"open already: close one and reload this one"}), CLOSE_S)
                await asyncio.wait_for(ws.close(code=1013, message=b"too many tabs"), CLOSE_S)  # try again later
            except asyncio.TimeoutError:
                if request.transport is not None:
                    request.transport.abort()
            return ws
        opened = datetime.datetime.now().strftime("%H:%M:%S")
        agent = request.headers.get("User-Agent", "a client").split(" ")[-1]
        self.who[ws] = f"the tab opened at {opened} from {request.remote} ({agent})"
        self.outbox[ws] = Outbox(self, ws, request.transport, self.who[ws])
        self.sockets.append(ws)
        self.worker.watched = True
        if self.driver is None:
            self.driver = ws
        self._roles()
        if self.last_scan is not None:
            self._tell(ws, self.last_scan)
        pace = Pace()
        try:
            async for msg in ws:
                within = pace.take()
                stop = not within and msg.type in (WSMsgType.TEXT, WSMsgType.BINARY) and is_stop(msg.data)
                if within or stop:  # a STOP ALL is taken over the rate too, and counted
                    await self._take(ws, msg)
                if not within and self._over(ws, pace, said=not stop):
                    break
                if self.outbox[ws].cut:  # what it sent before it was cut off is not taken
                    break
                # What a tab sent in one burst is all buffered: without a turn of
                # the loop here, another tab's STOP ALL waits behind all of it.
                await asyncio.sleep(0)
        finally:
            self.sockets.remove(ws)
            self.worker.watched = bool(self.sockets)
            self.who.pop(ws, None)
            self.outbox.pop(ws).close()
            mode = self.stop_mode.pop(ws, "release")
            mode = None if self.closing else mode
            if self.driver is ws:  # what it asked for ends with it, what it set moving too
                self.worker.abandon(mode)
                self.driver = None
                self._elect()
        return ws

    def _over(self, ws, pace, said: bool) -> bool:
        """A message over the tab's rate (pace.py), counted (and, said,
        refused unparsed); True once the tab has sent too many: then it is
        cut off."""
        text = pace.refuse()
        if pace.cut():
            self.outbox[ws].abort(pace.cut_text(self.who.get(ws, "a tab")))
            return True
        if said and text is not None:
            self._tell(ws, {"type": "error", "tag": None, "op": None, "text": text})
        return False

    def _tell(self, ws, msg):
        """Puts msg (a dict, or its text) in ws's outbox, never waiting."""
        box = self.outbox.get(ws)
        if box is not None:
            box.put(msg if isinstance(msg, str) else json.dumps(msg))

    def _elect(self):
        """With no tab driving: the first open tab that reads drives (one
        that has not read outbox.READING_MAX bytes is not given the role), and every
        tab is told its role. With none reading, none drives until one
        opens, asks or catches up."""
        if self.driver is None:
            self.driver = next((ws for ws in self.sockets if self.outbox[ws].reading()), None)
            if self.driver is not None:
                self._roles()

    def _cut(self, ws):
        """ws was aborted for not reading: it drives no more."""
        if self.driver is ws:
            self.worker.abandon(self.stop_mode.get(ws, "release"))
            self.driver = None
            self._elect()

    async def _take(self, ws, msg):
        """One message of a tab: a request, or an error said back (a
        malformed one, one the queue has no room for); the tab stays."""
        if msg.type not in (WSMsgType.TEXT, WSMsgType.BINARY):
            return
        tag = op = None
        try:
            if self.driver is None and self.outbox[ws].reading():  # none read when the driver closed
                self._elect()
            driving = ws is self.driver
            if not driving and len(msg.data) > WATCHER_MAX:
                await self._busy(ws)  # not parsed: it is not STOP ALL
                return
            if len(msg.data) > REQUEST_MAX:
                raise Malformed(f"{len(msg.data)} bytes long, over the {REQUEST_MAX} a request may be")
            ask = fields.parse(msg.data)
            tag, op = fields.tag(ask.get("tag")), ask.get("op")
            if op == "stopmode":  # any tab's: what its close stops the servos with, if it drives then
                self.stop_mode[ws] = fields.mode(ask.get("mode"))
                return
            if not driving and op != "stopall":  # any tab may stop
                await self._busy(ws, tag, op)  # its tag and op: the page answers the request that asked
                return
            self._dispatch(ask)
        except QueueFull as e:  # said where the page shows that action's output (tag, op)
            self._tell(ws, {"type": "error", "tag": tag, "op": op, "text": str(e)})
        except (Malformed, KeyError, TypeError, ValueError, OverflowError) as e:
            self._tell(ws, {"type": "error", "tag": tag, "op": op,
                            "text": f"servoctl ui: a malformed request: {e}"})
        except Exception as e:  # noqa: BLE001 - whatever a request does, the tab stays and hears why
            self._tell(ws, {"type": "error", "tag": tag, "op": op, "text": f"servoctl ui: {type(e).__name__}: {e}"})

    async def _busy(self, ws, tag=None, op=None):
        holder = self.who.get(self.driver, "no tab")  # none read when the driver closed
        self._tell(ws, {"type": "busy", "holder": holder, "tag": tag, "op": op,
                        "text": f"not run: {holder} drives the bus"})

    def _roles(self):
        """Tells every tab its role, through its outbox: none waits for another."""
        told = {role: json.dumps({"type": "hello", "role": role, "holder": holder, "stops": self.worker.stops,
                                  **self.about})
                for role, holder in (("driver", None), ("viewer", self.who.get(self.driver)))}
        for ws in list(self.sockets):
            self._tell(ws, told["driver" if ws is self.driver else "viewer"])

    def _dispatch(self, ask: dict):
        op, w = ask.get("op"), self.worker
        tag = ask.get("tag")
        if op == "stopall":
            try:
                mode = fields.mode(ask.get("mode"))
            except Malformed:
                w.stop_now("release")  # stopped all the same, and told why not as asked
                raise
            w.stop_now(mode)
        elif op == "run":
            w.submit(w.run, fields.strings(ask.get("argv", []), "argv"), tag)
        elif op == "scan":
            w.submit(w.scan, fields.flag(ask.get("all_bauds", False), "all_bauds"), tag)
        elif op == "items":
            w.submit(w.items, fields.servo_id(ask["id"], "id"), tag)
        elif op == "angle":
            w.submit(w.angle, fields.servo_id(ask["id"], "id"), tag)
        elif op == "jog":
            w.submit(w.jog, fields.servo_id(ask["id"], "id"), fields.number(ask["angle"], "angle"),
                     fields.whole(ask.get("stops", 0), "stops"), tag)
        elif op == "plot":
            ids = ask.get("ids", [])
            if not isinstance(ids, list):
                raise Malformed(f"ids must be a list, not {ids!r:.40}")
            w.submit(w.plot, [fields.servo_id(i, "ids") for i in ids], tag)
        elif op == "table":
            w.submit(w.table)
        else:
            raise Malformed(f"no such op: {op!r:.40}")

    # From the bus thread ----------------------------------------------------

    def publish(self, msg: dict):
        """Called on the bus thread: every tab hears it, serialised once,
        here, off the server's thread."""
        if self.loop is not None and not self.loop.is_closed():
            self.loop.call_soon_threadsafe(self._broadcast, msg, json.dumps(msg))

    def _broadcast(self, msg: dict, text: str):
        if msg.get("type") == "scan":
            self.last_scan = text
        for ws in list(self.sockets):
            self._tell(ws, text)

    def app(self) -> web.Application:
        a = web.Application(middlewares=[self.guard])
        a.on_response_prepare.append(self.no_frames)
        a.router.add_get("/", self.index)
        a.router.add_get("/ws", self.socket)
        a.router.add_get("/static/{name}", self.asset)
        return a


def _header_host(request):
    """The Host header's host name, without its port; None if absent or unreadable."""
    given = request.headers.get("Host")
    if not given:
        return None
    try:
        return URL(f"http://{given}/").host
    except ValueError:
        return None


def _own_origins(request) -> list:
    """The page's own origins: the address and port this connection
    reached (the listening socket's, not the Host header a rebound name
    sets), and on loopback the name localhost too."""
    sockname = request.transport.get_extra_info("sockname") if request.transport else None
    if not sockname:  # the connection has gone
        return []
    address, port = sockname[:2]
    ip = ipaddress.ip_address(address.split("%")[0])
    if ip.version == 6 and ip.ipv4_mapped:
        ip = ip.ipv4_mapped
    shown = f"[{ip}]" if ip.version == 6 else str(ip)
    return [f"http://{shown}:{port}"] + ([f"http://localhost:{port}"] if ip.is_loopback else [])


async def serve(page: Page, bind: str, port: int, ready, stop: asyncio.Event):
    """Serves until stop is set; ready(url_port) once listening."""
    page.loop = asyncio.get_running_loop()
    log = quiet.start()  # aiohttp's and asyncio's logs: one line a second at most, never blocking
    try:
        await _serve(page, bind, port, ready, stop)
    finally:
        log.close()


async def _serve(page: Page, bind: str, port: int, ready, stop: asyncio.Event):
    runner = web.AppRunner(page.app(), access_log=None, handle_signals=False, keepalive_timeout=KEEPALIVE_S)
    await runner.setup()
    page.doorman = Doorman(runner.server)
    # asyncio accepts up to its backlog of connections each time the loop
    # turns: a flood without the token (connections opened as fast as a
    # process can) held a tab's STOP ALL behind 100 accepts a turn, 20-245
    # ms. ACCEPT_BATCH a turn; the kernel's queue stays long (LISTEN_QUEUE)
    # so a page load is not dropped while the loop catches up.
    server = await page.loop.create_server(page.doorman, bind or None, port, backlog=ACCEPT_BATCH)
    for listening in server.sockets:
        with socket.socket(fileno=os.dup(listening.fileno())) as same:
            same.listen(LISTEN_QUEUE)
    ready(server.sockets[0].getsockname()[1])
    try:
        await stop.wait()
    finally:
        server.close()
        page.closing = True
        for ws in list(page.sockets):
            try:  # a tab that does not read would hold the close: CLOSE_S at most, then aborted
                await asyncio.wait_for(ws.close(), CLOSE_S)
            except asyncio.TimeoutError:
                if ws in page.outbox:
                    page.outbox[ws].abort()
        await runner.cleanup()
