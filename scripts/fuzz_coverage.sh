#!/usr/bin/env bash
# Line coverage of the motion, protection and profile code by the committed
# fuzz corpus (each seed run once under clang source-based coverage).
# Fails below FUZZ_COVERAGE_MIN percent (default 90) for any of them.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset coverage >/dev/null
cmake --build --preset coverage --target fuzz_servo >/dev/null
out=build/coverage/fuzz-coverage
rm -rf "$out"
mkdir -p "$out"
LLVM_PROFILE_FILE="$out/corpus.profraw" \
  ./build/coverage/tests/fuzz/fuzz_servo -runs=0 tests/fuzz/corpus >"$out/run.log" 2>&1
llvm-profdata merge -o "$out/corpus.profdata" "$out/corpus.profraw"
files=(motion/motion.c motion/setpoint.c motion/position.c motion/drive.c motion/planning.c
       motion/command_queue.c motion/control_tick.c motion/profile.c motion/stream.c motion/open_loop.c
       services/protection/protection.c
       services/storage/config_store.c services/storage/save_policy.c services/storage/fault_log.c
       services/protection/winding.c services/protection/bus_watchdog.c firmware/app/servo_safety.c)
llvm-cov report ./build/coverage/tests/fuzz/fuzz_servo -instr-profile="$out/corpus.profdata" \
  "${files[@]}" | tee "$out/report.txt"
# Columns: Filename Regions Missed Cover Functions Missed Executed Lines Missed Cover ...
awk -v min="${FUZZ_COVERAGE_MIN:-90}" '
  $1 ~ /\.c$/ { pct = $10; sub(/%/, "", pct); printf "line coverage %-36s %6.2f%%\n", $1, pct
                if (pct + 0 < min) { bad = 1 } }
  END { if (bad) { printf "below %d%% line coverage\n", min; exit 1 } }' "$out/report.txt"
