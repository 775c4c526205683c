#!/usr/bin/env python3
"""Runs the benchmarks under callgrind and prints their figures: the
protocol stack (instructions per received byte, request-to-response
latency) and the motion layer (instructions to plan a move, per control
tick). Counts are the host's (x86-64) instructions; see README."""
import argparse
import glob
import os
import re
import subprocess
import sys
import tempfile

CORTEX_M3_HZ = 72_000_000


def callgrind(binary, tmp):
    """Runs binary under callgrind; returns (stdout facts, {dump name: Ir},
    {dump name: file})."""
    out = os.path.join(tmp, os.path.basename(binary) + ".cg")
    run = subprocess.run(["valgrind", "--tool=callgrind", "--collect-atstart=no",
                          f"--callgrind-out-file={out}", binary],
                         capture_output=True, text=True)
    if run.returncode != 0:
        sys.stderr.write(run.stderr)
        raise SystemExit(f"{binary} failed under callgrind")
    facts = dict(line.split() for line in run.stdout.splitlines() if line.strip())
    totals, files = {}, {}
    for path in glob.glob(out + "*"):
        text = open(path).read()
        trigger = re.search(r"^desc: Trigger: Client Request: (\S+)", text, re.M)
        total = re.search(r"^(?:totals|summary): (\d+)", text, re.M)
        if trigger and total:
            totals[trigger.group(1)] = int(total.group(1))
            files[trigger.group(1)] = path
    return facts, totals, files


def inclusive(path, functions):
    """Inclusive Ir of the named functions in one callgrind dump."""
    annotated = subprocess.run(["callgrind_annotate", "--inclusive=yes", path],
                               capture_output=True, text=True, check=True).stdout
    found = {}
    for m in re.finditer(r"^\s*([\d,]+) \([^)]*\)\s+\S*?:(\w+) ", annotated, re.M):
        if m.group(2) in functions and m.group(2) not in found:
            found[m.group(2)] = int(m.group(1).replace(",", ""))
    return found


def protocol(binary, tmp):
    facts, totals, files = callgrind(binary, tmp)
    stream_bytes = int(facts["stream_bytes"])
    # The main loop also runs control ticks (sensors, protection, motion):
    # they are not the protocol's cost.
    tick = "servo_control_tick"
    inc = inclusive(files["stream"], {"frame_rx_feed", "servo_poll", tick})
    framer = inc["frame_rx_feed"]
    main_loop = inc["servo_poll"] - inc.get(tick, 0)
    for name, path in files.items():
        if name == "idle_poll" or name.startswith("latency_"):
            totals[name] -= inclusive(path, {tick}).get(tick, 0)
    print(f"protocol: mixed stream of {stream_bytes} bytes, {facts['stream_messages']} messages, "
          f"{facts['frames_for_all']} requests delivered, "
          f"{facts['responses_skipped']} responses skipped")
    print(f"  receive interrupt (framer):     {framer / stream_bytes:5.1f} instructions per byte")
    print(f"  main loop (dispatch, respond):  {main_loop / stream_bytes:5.1f} instructions per byte")
    print(f"  framer + dispatcher:            {(framer + main_loop) / stream_bytes:5.1f} "
          f"instructions per byte (target <= 60)")
    print(f"  idle main-loop pass: {totals['idle_poll']} instructions (control ticks excluded)")
    print("  last request byte -> response handed to the UART:")
    for name in sorted(k for k in totals if k.startswith("latency_")):
        ins = totals[name]
        us = ins / CORTEX_M3_HZ * 1e6
        print(f"    {name[8:]:<12} {ins:6d} instructions  (~{us:.1f} us at 72 MHz, 1 instr/cycle; "
              f"target 50 us)")


def motion(binary, tmp):
    facts, totals, files = callgrind(binary, tmp)
    ticks = int(facts["ticks"])
    print("motion: planning one move (motion_submit: clamps, timing, profile), target <= 2000")
    for name in ("plan_interval", "plan_velocity", "plan_short_stroke", "plan_preempt"):
        print(f"    {name[5:]:<14} {totals[name]:6d} instructions")
    inc = inclusive(files["ticks"], {"profile_position", "controller_position",
                                     "encoder_read", "motor_drive"})
    core = inc["profile_position"] + inc["controller_position"]
    hal = inc["encoder_read"] + inc["motor_drive"]
    print(f"  one control tick, mean of {ticks} (target <= 150):")
    print(f"    planner evaluation + controller   {core / ticks:6.1f} instructions")
    print(f"    whole tick less the HAL double    {(totals['ticks'] - hal) / ticks:6.1f} instructions "
          f"(+ encoder tracking, velocity filter, state)")
    print(f"    whole tick with the HAL double    {totals['ticks'] / ticks:6.1f} instructions")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("bench_dir", help="folder holding bench_protocol and bench_motion "
                                      "(build/bench/tests/bench)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        protocol(os.path.join(args.bench_dir, "bench_protocol"), tmp)
        motion(os.path.join(args.bench_dir, "bench_motion"), tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
