#!/usr/bin/env bash
# A long mixed storm against three simulated servos (the ASan + UBSan build
# of servo_sim): garbage at line rate, preempting moves, answered moves,
# Sync Monitor rounds, config writes alone and in bursts that fill the
# store's pages, releases and quiet (so the spare page is erased), injected
# faults and power cuts by SIGKILL. Prints a summary (frames lost,
# collisions, ticks dropped, configs corrupted, acknowledged changes lost,
# sanitizer findings) and fails unless every count is 0.
# Not part of the test command: it takes MINUTES (default 30).
#   bash scripts/storm.sh [MINUTES] [SEED]
# Output: build/storm-SEED/summary.txt, summary.json, events.log, servo_sim.stderr
# (one folder a seed: two seeds can run side by side)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
cmake --preset host >/dev/null
cmake --build --preset host --target servo_sim >/dev/null
exec .venv/bin/python tests/storm/storm.py --minutes "${1:-30}" --seed "${2:-1}" --out "build/storm-${2:-1}"
