#!/usr/bin/env bash
# The demo, for now: builds the STM32F103 image and shows its footprint, runs
# the unit tests, and prints the protocol benchmark. (A simulated servo driven
# by the PC tool joins it with the simulator.)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

echo; echo "== firmware image for the STM32F103"
cmake --preset arm >/dev/null
cmake --build --preset arm | grep -E '^image:' || true
ls -l build/arm/firmware/boards/stm32f103/servo_stm32f103.bin

echo; echo "== unit tests"
cmake --preset host >/dev/null
cmake --build --preset host >/dev/null
ctest --preset host | tail -n 3

echo; echo "== protocol benchmark (callgrind)"
cmake --preset bench >/dev/null
cmake --build --preset bench >/dev/null
.venv/bin/python tests/bench/run_bench.py build/bench/tests/bench
