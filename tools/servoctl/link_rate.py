"""The host's baud rate on a socket:// link. A TCP link carries bytes, not a
rate: the far end (servo_sim, a virtual board, a serial server) decides
what rate its wire runs at, and pyserial's baudrate on a socket does
nothing. A simulator takes its host's rate on its control port
(`hostbaud BAUD`); given that port (--sim-control, env
SERVOCTL_SIM_CONTROL), servoctl sets it there for --baud and after a
`config set N baud`. Without it, --baud on socket:// is refused (it would
be ignored) and a baud change says what to do, instead of losing the bus
with no word."""
import contextlib

from . import registers
from .errors import ServoError, UsageError

DEFAULT_BAUD = 115200


def is_socket(port) -> bool:
    return bool(port) and port.startswith("socket://")


def _control_port(address) -> int:
    host, _, port = str(address).rpartition(":")  # a number given as one (a config's int) too
    if host not in ("", "127.0.0.1", "localhost"):
        raise UsageError(f"--sim-control is a simulator's control port on this PC (PORT or "
                         f"127.0.0.1:PORT), not {address}")
    try:
        return int(port)
    except ValueError:
        raise UsageError(f"--sim-control takes a port number, not {address!r}") from None


def _control(address: str, line: str) -> str:
    from .sim import control_command

    return control_command(_control_port(address), line)


def simulator(sim_control):
    """The simulator whose control port is given (servoctl.sim.Simulator,
    for its clock_s), or None: with it, servoctl's bus waits on the
    simulated clock, so a simulator that runs behind the wall clock on a
    busy PC is not taken for a servo that does not answer."""
    if not sim_control:
        return None
    from .sim import Simulator

    return Simulator.running(_control_port(sim_control))


def open_rate(port, baud, sim_control) -> int:
    """The rate to open the link at: --baud, or 115200. On socket:// an
    explicit --baud is set on the simulator's control port, or refused;
    without --baud, the simulator's host rate read there (host_baud), so
    the wire's limits (stream, bench) are a 1 Mbaud wire's after hostbaud."""
    if baud is None and is_socket(port) and sim_control:
        return _host_rate(sim_control) or DEFAULT_BAUD
    if baud is None or not is_socket(port):
        return baud or DEFAULT_BAUD
    if not sim_control:
        raise UsageError(f"socket:// carries no baud rate: --baud {baud} would be ignored. On a "
                         f"simulator, send 'hostbaud {baud}' to its control port, or give "
                         f"--sim-control PORT and servoctl does it")
    _control(sim_control, f"hostbaud {baud}")
    return baud


def _host_rate(sim_control):
    """The simulator's host rate (host_baud in its state line), or None."""
    words = dict(w.split("=", 1) for w in _control(sim_control, "state").split() if "=" in w)
    rate = words.get("host_baud", "")
    return int(rate) if rate.isdigit() else None


def set_rate(bus, sim_control, rate: int) -> None:
    """The host's rate on the bus: the port's, and on socket:// with the
    control port given the simulator's host rate (hostbaud) too."""
    if is_socket(bus.port) and sim_control and rate != bus.serial.baudrate:
        _control(sim_control, f"hostbaud {rate}")
    bus.serial.baudrate = rate


@contextlib.contextmanager
def restored(bus, sim_control):
    """The host's rate as it was once the block ends (scan --all-bauds)."""
    rate = bus.serial.baudrate
    try:
        yield
    finally:
        set_rate(bus, sim_control, rate)


def after_set(bus, args, name: str, value: int) -> None:
    """After `config set N name value`: a baud change says what to do."""
    rate = registers.BAUD_RATES.get(value) if name == "baud" else None
    if rate is not None and (is_socket(bus.port) or rate != bus.serial.baudrate):
        print(after_change(bus, f"servo {args.id}", rate, args.sim_control))


def after_load(bus, args, servo_id: int, before: int, now: int) -> list:
    """After `config load --with-link`: a baud change as after_set; the
    notes the load reports (the servo's new ID)."""
    if now != before:
        print(after_change(bus, f"servo {servo_id}", registers.BAUD_RATES[now], args.sim_control))
    return [f"now ID {servo_id}"] if servo_id != args.id else []


def after_change(bus, who: str, rate: int, sim_control) -> str:
    """What to do now that a servo ("servo 3", "servos 1, 2") speaks `rate`,
    or what was done (the simulator's host rate set on its control port)."""
    speaks = "speaks" if who.startswith("servo ") else "speak"
    if not is_socket(bus.port):
        return f"{who} now {speaks} {rate} baud: give --baud {rate} from now on"
    if sim_control:
        _control(sim_control, f"hostbaud {rate}")
        bus.serial.baudrate = rate
        return (f"{who} now {speaks} {rate} baud: the simulator's host rate is set to "
                f"{rate} too (hostbaud on its control port)")
    return (f"{who} now {speaks} {rate} baud, and socket:// carries no baud rate: on a "
            f"simulator, send 'hostbaud {rate}' to its control port (or give --sim-control PORT "
            f"and servoctl does it) to reach it again")


def no_reply_hint(bus, port, sim_control, rate: int) -> str:
    """What a NoReply on socket:// where no answer at all came adds: the
    simulator's host rate, read on its control port where given, else that
    it may have been changed (a --sim-control --baud earlier outlives that
    servoctl)."""
    if not is_socket(port) or getattr(bus, "heard", False):
        return ""
    if sim_control:
        try:
            host = _host_rate(sim_control)
        except ServoError:  # a hint only: the NoReply is the error
            host = None
        if host and host != rate:
            return (f"; the simulator's host rate is {host} baud, not {rate}: give --baud {host} "
                    f"--sim-control {sim_control}")
        if host:  # servoctl took the host rate; the servo may speak another
            return (f"; the simulator's host rate is {host} baud: if the servo speaks another, "
                    f"give --baud RATE --sim-control {sim_control}")
        return ""
    return ("; if the simulator's host rate was changed (hostbaud, or an earlier --sim-control with "
            "--baud), give --baud and --sim-control to set it")
