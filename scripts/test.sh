#!/usr/bin/env bash
# Runs every test: unit tests under ASan + UBSan; the ARM images with their
# flash/RAM budget and soft-float checks; pytest: the PC tool, the firmware on
# simulated servos (servoctl and the maker's SDK), the real ARM image under
# QEMU; a bounded fuzz run (at least 5000 executions per second) and the
# corpus's line coverage (at least 90 %).
# FUZZ_SECONDS sets the fuzz run's length (default 60).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

step() { printf '\n== %s\n' "$*"; }

step "unit tests (host, AddressSanitizer + UndefinedBehaviorSanitizer)"
cmake --preset host >/dev/null
cmake --build --preset host
ctest --preset host | tee build/host/ctest.log
unit=$(sed -nE 's/.*tests passed, 0 tests failed out of ([0-9]+).*/\1/p' build/host/ctest.log)

step "ARM images (STM32F103, and the QEMU board): budget and soft-float checks"
cmake --preset arm >/dev/null
cmake --build --preset arm

step "Cortex-M0 image (STM32F030K6) and its bootloader: 4 KB RAM, 16 KB flash goal (a ceiling until met), 4 KB bootloader, soft-float"
cmake --preset arm-m0 >/dev/null
cmake --build --preset arm-m0

step "target benchmark: Thumb instructions on the Cortex-M3 and M0 under QEMU, against issue 10's budgets"
for cpu in m3 m0; do
  cmake --preset "target-bench-$cpu" >/dev/null
  cmake --build --preset "target-bench-$cpu" >/dev/null
done
python3 tests/bench/target/run_target_bench.py --check --json build/target-bench.json

step "PC tool, simulator, maker's SDK and QEMU board tests (pytest)"
(cd tools && ../.venv/bin/python -m pytest -q) | tee build/host/pytest.log
tools_passed=$(sed -nE 's/^([0-9]+) passed.*/\1/p' build/host/pytest.log)

step "fuzzing the whole servo for ${FUZZ_SECONDS:-60} s (libFuzzer, ASan + UBSan, -O2)"
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target fuzz_servo
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# New inputs go to the scratch folder; the committed seeds stay as they are.
# Inputs up to 256 bytes: a dozen requests and as many clock, horn, sensor,
# flash and power events.
./build/fuzz/tests/fuzz/fuzz_servo -max_total_time="${FUZZ_SECONDS:-60}" -seed=1 -max_len=256 \
  -print_final_stats=1 "$work" tests/fuzz/corpus 2>"$work/log" || {
  tail -n 60 "$work/log" >&2
  echo "fuzzing found a failure (crash input saved in the working directory)" >&2
  exit 1
}
grep -E '^(#[0-9]+\s+DONE|stat::number_of_executed_units|stat::average_exec_per_sec)' "$work/log"
rate=$(sed -nE 's/^stat::average_exec_per_sec:\s+([0-9]+)/\1/p' "$work/log")
if [ "${rate:-0}" -lt "${FUZZ_MIN_EXEC_PER_S:-5000}" ]; then
  echo "the fuzzer ran ${rate:-0} executions per second, below ${FUZZ_MIN_EXEC_PER_S:-5000}" >&2
  exit 1
fi

step "line coverage of motion, protection and the config store by the fuzz corpus (>= 90 %)"
bash scripts/fuzz_coverage.sh

echo
# CTest programs, pytest tests, the fuzz run, its coverage, the ARM image
# checks (Cortex-M3 boards, the Cortex-M0 board) and the target benchmark
# (its calibration).
echo "summary: $((unit + tools_passed + 5)) passed, 0 failed"
