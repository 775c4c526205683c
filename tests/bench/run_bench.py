#!/usr/bin/env python3
"""Runs bench_protocol under callgrind and prints instructions per received
byte and per request-to-response latency. Instruction counts are the host's
(x86-64); see README for how they relate to the Cortex-M3 target."""
import argparse
import glob
import os
import re
import subprocess
import sys
import tempfile

CORTEX_M3_HZ = 72_000_000


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("binary", help="path to bench_protocol (bench preset)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "callgrind.out")
        run = subprocess.run(
            ["valgrind", "--tool=callgrind", "--collect-atstart=no",
             f"--callgrind-out-file={out}", args.binary],
            capture_output=True, text=True)
        if run.returncode != 0:
            sys.stderr.write(run.stderr)
            return run.returncode
        facts = dict(line.split() for line in run.stdout.splitlines() if line.strip())
        totals = {}
        stream_file = None
        for path in glob.glob(out + "*"):
            text = open(path).read()
            trigger = re.search(r"^desc: Trigger: Client Request: (\S+)", text, re.M)
            total = re.search(r"^(?:totals|summary): (\d+)", text, re.M)
            if trigger and total:
                totals[trigger.group(1)] = int(total.group(1))
                if trigger.group(1) == "stream":
                    stream_file = path
        # The firmware's share of the stream: the receive-interrupt path and
        # the main loop, each inclusive of what it calls; not the harness.
        annotated = subprocess.run(["callgrind_annotate", "--inclusive=yes", stream_file],
                                   capture_output=True, text=True, check=True).stdout
        inclusive = {}
        for m in re.finditer(r"^\s*([\d,]+) \([^)]*\)\s+\S*?:(frame_rx_feed|servo_poll) ",
                             annotated, re.M):
            inclusive[m.group(2)] = int(m.group(1).replace(",", ""))
    stream_bytes = int(facts["stream_bytes"])
    framer = inclusive["frame_rx_feed"]
    main_loop = inclusive["servo_poll"]
    print(f"mixed stream: {stream_bytes} bytes, {facts['stream_messages']} messages, "
          f"{facts['frames_for_all']} requests delivered, "
          f"{facts['responses_skipped']} responses skipped")
    print(f"  receive interrupt (framer):     {framer / stream_bytes:5.1f} instructions per byte")
    print(f"  main loop (dispatch, respond):  {main_loop / stream_bytes:5.1f} instructions per byte")
    print(f"  framer + dispatcher:            {(framer + main_loop) / stream_bytes:5.1f} "
          f"instructions per byte (target <= 60)")
    print(f"idle main-loop pass: {totals['idle_poll']} instructions")
    print("last request byte -> response handed to the UART:")
    for name in sorted(k for k in totals if k.startswith("latency_")):
        ins = totals[name]
        us = ins / CORTEX_M3_HZ * 1e6
        print(f"  {name[8:]:<12} {ins:6d} instructions  (~{us:.1f} us at 72 MHz, 1 instr/cycle; target 50 us)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
