"""servoctl sim: the simulator, or a virtual board, for a person at the
command line."""
import sys


class _Terminated(Exception):
    """SIGTERM: the simulator stopped as asked, exit 0."""


def _terminate(signum, frame):
    raise _Terminated


def cmd_sim(args):
    """Runs servo_sim until Ctrl-C (exit 130, as every command interrupted)
    or SIGTERM (exit 0); either stops it cleanly and removes a state folder
    it made."""
    import signal

    from ..errors import EXIT_INTERRUPTED, UsageError
    from ..sim import Simulator

    if args.tcp is not None and args.link:
        raise UsageError("--link names the simulator's pty: not with --tcp")
    tcp_port = args.tcp if args.tcp else None
    sim = Simulator(ids=args.ids or [1], tcp=args.tcp is not None, link=args.link,
                    state_dir=args.state, tcp_port=tcp_port, plant=args.plant,
                    board=None if args.board == "host" else args.board, host_link=args.host_link)
    previous = signal.signal(signal.SIGTERM, _terminate)
    code = 0
    try:
        sim.start()
        print(f"simulator running: bus {sim.url}, control 127.0.0.1:{sim.control_port}", flush=True)
        # Both: with the control port servoctl waits on the simulator's clock.
        print(f"  export SERVOCTL_PORT={sim.url} SERVOCTL_SIM_CONTROL={sim.control_port}", flush=True)
        print(f"  e.g. servoctl --port {sim.url} --sim-control {sim.control_port} scan  (Ctrl-C stops)", flush=True)
        sim.process.wait()
    except KeyboardInterrupt:
        code = EXIT_INTERRUPTED
    except _Terminated:
        pass
    finally:
        sim.stop()
        signal.signal(signal.SIGTERM, previous)
    print("simulator stopped")
    if code:
        print("servoctl: interrupted", file=sys.stderr)
    return code

# This module's commands without a bus: they start their own (cli/app.py).
NO_BUS = {
    "sim": cmd_sim,
}
