"""What an unplugged servo costs the C robot loop (docs/c-library.md, "A
silent servo"): build/host's sb_loop_bench, 100 cycles, on servo_sim's
clock, with no servo, a middle one and the last one unplugged
(`unplug 1 ID`), at 115 200 and 1 000 000 baud. Run from the repository:
    .venv/bin/python tools/servobus/examples/silent_cost.py"""
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, "scripts")
from bench_sim import at_baud  # noqa: E402  the simulated servos at a rate

BENCH, CYCLES = Path("build/host/tools/servobus/sb_loop_bench"), 100
print("| servos | baud | unplugged | ms a cycle | wire's cycle, ms | missed |")
print("|---:|---:|---|---:|---:|---:|")
for baud, count in ((115200, 6), (1000000, 6)):
    with at_baud(list(range(1, count + 1)), baud) as sim:
        clock = str(Path(sim.state_dir) / "bus.clock")
        for silent in (None, 3, count):
            if silent:
                sim.control(f"unplug 1 {silent}")
            out = subprocess.run([str(BENCH), sim.url.removeprefix("socket://"), clock, str(baud), str(count),
                                  str(CYCLES)], capture_output=True, text=True, timeout=300).stdout
            if silent:
                sim.control(f"unplug 0 {silent}")
            w = dict(zip(*[iter(out.split())] * 2))
            print(f"| {count} | {baud} | {silent or 'none'} | {1000 * float(w['seconds']) / CYCLES:.2f} "
                  f"| {1000 / float(w['wire']):.2f} | {w['missed']} |")
