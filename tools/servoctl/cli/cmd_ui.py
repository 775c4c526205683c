"""servoctl ui: the bench in a web browser, a page served on this computer
for the bus servoctl is connected to (servoctl/ui: the server, the bus
thread and the page). Its first line of output is the page's address with
its token; Ctrl-C stops it."""
import asyncio
import secrets
import signal
import sys

from .. import __version__
from ..errors import UsageError


def global_argv(args) -> list:
    """The options every command the page runs is parsed with: this bus's."""
    argv = ["--port", args.port, "--timeout", str(args.timeout)]
    if args.sim_control:
        argv += ["--sim-control", str(args.sim_control)]
    if args.baud:
        argv += ["--baud", str(args.baud)]
    return argv


def cmd_ui(bus, args):
    from ..ui.server import Page, serve  # aiohttp loads for this command alone
    from .live import has_display
    from ..ui.opener import PageOpener
    from ..ui.worker import Worker

    token = secrets.token_urlsafe(18)
    about = {"port": args.port, "simulator": bool(args.sim_control), "version": __version__}
    loopback = args.bind in ("127.0.0.1", "localhost", "::1")
    page = Page(None, token, about, hosts={"127.0.0.1", "localhost", "::1"} if loopback else None)
    worker = Worker(bus, global_argv(args), page.publish, files=args.files)
    page.worker = worker
    opener = PageOpener()

    def ready(port: int):
        host = "127.0.0.1" if args.bind in ("0.0.0.0", "::", "") else args.bind
        if ":" in host:  # an IPv6 address goes in brackets (RFC 3986): http://[::1]:PORT/
            host = f"[{host}]"
        url = f"http://{host}:{port}/?token={token}"
        print(f"servoctl ui: {url}", flush=True)
        if not loopback:
            print(f"servoctl ui: warning: listening on {args.bind}: anyone who reaches it with the "
                  f"token drives the bus", file=sys.stderr, flush=True)
        print(f"servoctl ui: the page's files are in {worker.files.root}; Ctrl-C stops", file=sys.stderr, flush=True)
        if args.no_browser:
            return
        if not has_display():  # a console browser would take this terminal
            print("servoctl ui: no display (DISPLAY and WAYLAND_DISPLAY are unset): open the address "
                  "in a browser", file=sys.stderr, flush=True)
        elif not opener.open(url):  # a local file that forwards: no token on the browser's command line
            print("servoctl ui: no browser found: open the address in one", file=sys.stderr, flush=True)

    async def main():
        stop = asyncio.Event()
        loop = asyncio.get_running_loop()
        for sig in (signal.SIGINT, signal.SIGTERM):
            loop.add_signal_handler(sig, stop.set)
        await serve(page, args.bind, args.listen, ready, stop)

    worker.start()
    try:
        asyncio.run(main())
    except OSError as e:  # the port is taken, the address is not this computer's
        raise UsageError(f"ui: cannot listen on {args.bind} port {args.listen}: {e.strerror or e}") from None
    finally:
        worker.stop()
        opener.close()
    print("servoctl ui: stopped", file=sys.stderr)
    return 0


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "ui": cmd_ui,
}
