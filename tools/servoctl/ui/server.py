"""`servoctl ui`'s web server (aiohttp): the page, its assets and one
WebSocket, all behind the random token in the page's address. A request
without the token, or from a page of another origin (a web site asking the
local server to move the robot), is refused with 403. One tab drives the
bus; another is told which one does and only watches until that one
closes."""
import asyncio
import datetime
import hmac
import json
from pathlib import Path

from aiohttp import WSMsgType, web

from .worker import QueueFull

STATIC = Path(__file__).parent / "static"
ASSETS = {p.name for p in STATIC.iterdir() if p.is_file()}


class Page:
    def __init__(self, worker, token: str, about: dict, hosts=None):
        self.worker, self.token, self.about = worker, token, about
        self.hosts = hosts  # the names the page may be asked by (DNS rebinding); None: any
        self.sockets = []   # every open tab's WebSocket, in order of opening
        self.driver = None  # the tab that drives the bus
        self.who = {}       # ws: how the other tabs are told of it
        self.loop = None

    # Safety -----------------------------------------------------------------

    def _refusal(self, request, need_origin: bool):
        given = request.query.get("token", "")
        if not hmac.compare_digest(given.encode(), self.token.encode()):
            return "refused: the address lacks this session's token (see servoctl ui's first line)"
        host = (request.url.host or "").strip("[]")
        if self.hosts is not None and host not in self.hosts:
            return f"refused: a request for host {host!r}, not this computer's (DNS rebinding?)"
        origin = request.headers.get("Origin")
        own = f"{request.scheme}://{request.host}"
        if origin is None and need_origin:
            return "refused: a WebSocket without an Origin"
        if origin is not None and origin != own:
            return f"refused: a request from another origin ({origin}), not {own}"
        return None

    @web.middleware
    async def guard(self, request, handler):
        why = self._refusal(request, need_origin=request.path == "/ws")
        if why:
            return web.Response(status=403, text=why + "\n")
        return await handler(request)

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
        ws = web.WebSocketResponse(heartbeat=20)
        await ws.prepare(request)
        opened = datetime.datetime.now().strftime("%H:%M:%S")
        agent = request.headers.get("User-Agent", "a client").split(" ")[-1]
        self.who[ws] = f"the tab opened at {opened} from {request.remote} ({agent})"
        self.sockets.append(ws)
        if self.driver is None:
            self.driver = ws
        await self._roles()
        try:
            async for msg in ws:
                if msg.type != WSMsgType.TEXT:
                    continue
                try:
                    ask = json.loads(msg.data)
                except ValueError:
                    continue
                if not isinstance(ask, dict):  # [1], 5, "x": not a request; the tab stays
                    continue
                if ws is not self.driver and ask.get("op") != "stopall":  # any tab may stop
                    await ws.send_json({"type": "busy", "holder": self.who[self.driver],
                                        "text": f"{self.who[self.driver]} drives the bus"})
                    continue
                try:
                    self._dispatch(ask)
                except QueueFull as e:
                    await _send(ws, {"type": "error", "tag": ask.get("tag"), "text": str(e)})
                except (KeyError, TypeError, ValueError) as e:  # {"op": "items"} without its id
                    await ws.send_json({"type": "error", "text": f"servoctl ui: a malformed request: {e!r}"})
        finally:
            self.sockets.remove(ws)
            self.who.pop(ws, None)
            if self.driver is ws:
                self.driver = self.sockets[0] if self.sockets else None
                await self._roles()
        return ws

    async def _roles(self):
        for ws in list(self.sockets):
            driving = ws is self.driver
            await _send(ws, {"type": "hello", "role": "driver" if driving else "viewer",
                             "holder": None if driving else self.who[self.driver], **self.about})

    def _dispatch(self, ask: dict):
        op, w = ask.get("op"), self.worker
        tag = ask.get("tag")
        if op == "run":
            w.submit(w.run, [str(a) for a in ask.get("argv", [])], tag)
        elif op == "scan":
            w.submit(w.scan, bool(ask.get("all_bauds")), tag)
        elif op == "items":
            w.submit(w.items, int(ask["id"]))
        elif op == "plot":
            w.submit(w.plot, ask.get("ids", []))
        elif op == "table":
            w.submit(w.table)
        elif op == "stopall":
            w.stop_now("damping" if ask.get("mode") == "damping" else "release")

    # From the bus thread ----------------------------------------------------

    def publish(self, msg: dict):
        """Called on the bus thread: every tab hears it."""
        if self.loop is not None and not self.loop.is_closed():
            self.loop.call_soon_threadsafe(self._broadcast, msg)

    def _broadcast(self, msg: dict):
        for ws in list(self.sockets):
            asyncio.ensure_future(_send(ws, msg))

    def app(self) -> web.Application:
        a = web.Application(middlewares=[self.guard])
        a.router.add_get("/", self.index)
        a.router.add_get("/ws", self.socket)
        a.router.add_get("/static/{name}", self.asset)
        return a


async def _send(ws, msg):
    if not ws.closed:
        try:
            await ws.send_str(json.dumps(msg))
        except (ConnectionError, RuntimeError):
            pass


async def serve(page: Page, bind: str, port: int, ready, stop: asyncio.Event):
    """Serves until stop is set; ready(url_port) once listening."""
    page.loop = asyncio.get_running_loop()
    runner = web.AppRunner(page.app(), access_log=None, handle_signals=False)
    await runner.setup()
    site = web.TCPSite(runner, bind, port)
    await site.start()
    bound = runner.addresses[0][1]
    ready(bound)
    try:
        await stop.wait()
    finally:
        for ws in list(page.sockets):
            await ws.close()
        await runner.cleanup()
