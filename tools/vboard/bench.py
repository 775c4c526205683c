"""How fast the virtual boards run: simulated seconds per wall second, with
the runner unpaced (it follows the wall clock only when serving a host):

    python -m vboard.bench [--board stm32f103|stm32f030k6] [--seconds S]

Three cases per board, each in this one process (one core):
- idle: one board, nothing on the bus;
- stream: one board, a Ping to it every PING_PERIOD_S at 115200 baud, the
  answers counted (6 bytes out, 6 back: 72 % of the wire);
- bus of 3: three boards, the same stream to each in turn.

A speed of 1.0 keeps up with real time; below it, every client with its own
timeouts sees a slow servo. The figures go in docs/virtual-boards.md.
VBOARD_SKIP=0 emulates every idle pass the cores would skip (idle_skip.py).
--mpu guard sets the Cortex-M3's MPU as a firmware guarding its stack
would (a 32-byte no-access region at the stack's bottom, PRIVDEFENA: one
hooked range); --mpu all without PRIVDEFENA (a 4 GB read-write region
under the guard: every access hooked), for what the MPU's hooks cost."""
import argparse
import sys
import tempfile
import time
from types import SimpleNamespace

from servoctl import protocol as p

from . import mpu
from .board import PARTS
from .run import MAX_SLICE_S, Runner

PING_PERIOD_S = 1.5e-3   # request 0.52 ms, answer 0.52 ms, and the turnarounds
ANSWER = 6               # a Ping's answer, bytes
DRAIN_S = 5e-3           # the last request and its answer, and the servo's turnaround


def runner_for(board: str, ids, state_dir: str) -> Runner:
    args = SimpleNamespace(board=board, id=list(ids), state=state_dir, supply=7400.0, ambient=25.0, plant=None,
                           app=None, tcp=0, link=None, host_link="usb", clock="wall")
    runner = Runner(args)
    runner.power_up()
    return runner


def measure(runner: Runner, seconds: float, ping_ids=(), cpu: list = None) -> tuple:
    """Runs seconds of simulated time as fast as it goes; returns (speed,
    pings sent, answers heard), and appends to cpu, if given, simulated
    seconds per second of this process's CPU time (what a machine shared
    with other work still shows). The answers still on the wire at the
    end are waited for, untimed, before they are counted."""
    start_sim, start_wall, start_cpu = runner.now_s, time.perf_counter(), time.process_time()
    next_ping, sent, k = runner.now_s, 0, 0
    runner.bus.to_host.clear()
    while runner.now_s - start_sim < seconds:
        if ping_ids and runner.now_s >= next_ping - MAX_SLICE_S:  # on the wire at next_ping
            for byte in p.request_frame(p.PING, bytes([ping_ids[k % len(ping_ids)]])):
                runner.bus.queue_host(byte, next_ping)
            k, sent, next_ping = k + 1, sent + 1, next_ping + PING_PERIOD_S
        runner.step()
        runner.bus.flush_to_host(runner.now_s)  # what the adapter has handed over
    wall = time.perf_counter() - start_wall
    speed = (runner.now_s - start_sim) / wall
    if cpu is not None:
        cpu.append((runner.now_s - start_sim) / (time.process_time() - start_cpu))
    drained = max(runner.now_s, next_ping) + DRAIN_S
    while runner.now_s < drained:
        runner.step()
        runner.bus.flush_to_host(runner.now_s)
    return speed, sent, len(runner.bus.to_host) // ANSWER


def guard_stack(board, how: str) -> None:
    """The M3's MPU as --mpu says (nothing on the M0, which has none)."""
    if how == "off" or not board.core.v7m or board.injector.facts is None:
        return
    bottom = board.injector.facts[1]
    regions = {1: (bottom, mpu.no_access())}
    if how == "all":
        regions[0] = (0, (3 << 24) | (31 << 1) | 1)  # 4 GB, AP 011: read-write
    mpu.configure(board.core, regions, mpu.CTRL_ENABLE | (mpu.CTRL_PRIVDEFENA if how == "guard" else 0))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m vboard.bench", description=__doc__.split("\n\n")[0])
    ap.add_argument("--board", choices=sorted(PARTS), action="append", help="default: both")
    ap.add_argument("--seconds", type=float, default=2.0, help="simulated seconds per case (default 2)")
    ap.add_argument("--mpu", choices=("off", "guard", "all"), default="off", help="the M3's MPU (default off)")
    args = ap.parse_args(argv)
    print(f"{'board':<12} {'case':<8} {'speed (sim s / wall s)':>23} {'(/ CPU s)':>10} {'answered':>10}")
    worst = float("inf")
    for board in args.board or sorted(PARTS):
        cases = (("idle", (1,), ()), ("stream", (1,), (1,)), ("bus of 3", (1, 2, 3), (1, 2, 3)))
        for name, ids, pings in cases:
            with tempfile.TemporaryDirectory(prefix="vboard-bench-") as state:
                runner = runner_for(board, ids, state)
                for b in runner.boards:
                    guard_stack(b, args.mpu)
                cpu = []
                try:
                    speed, sent, heard = measure(runner, args.seconds, pings, cpu)
                finally:
                    runner.bus.close()
                    runner.control.close()
                    runner.clock.close()
            answered = f"{heard}/{sent}" if sent else "-"
            print(f"{board:<12} {name:<8} {speed:>22.2f}x {cpu[0]:>9.2f}x {answered:>10}", flush=True)
            worst = min(worst, speed)
            if sent and heard < sent:
                print(f"vboard.bench: {board} answered {heard} of {sent} pings", file=sys.stderr)
                return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
