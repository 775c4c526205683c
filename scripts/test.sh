#!/usr/bin/env bash
# Runs every test: unit tests under ASan + UBSan; the ARM images with their
# flash/RAM budget and soft-float checks; the target benchmark; pytest: the
# PC tool, the firmware on simulated servos (servoctl and the maker's SDK),
# the real ARM image under QEMU; a fuzz run of a fixed number of inputs and
# the corpus's line coverage (at least 90 %).
# Every step runs whatever an earlier one did; each failure is named at the
# end, and the last line counts the checks: "summary: N passed, N failed"
# (each CTest program and pytest test, and each other step as one).
# The unit tests, the target benchmark and arithmetic, the fuzz run and its
# coverage need nothing of pytest's: they run beside its parallel pass, on
# the CPU its tests leave, their output printed after pytest's.
# FUZZ_RUNS sets the fuzz run's length in inputs (default 200000): a fixed
# amount of fuzzing, which a busy machine makes slower, not smaller.
set -uo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh || { echo "setup failed: nothing was tested" >&2; exit 1; }
mkdir -p build
# The maker's LeRobot plugin's environment (torch: several GB), once a
# machine; the demo does without it. Made (or, already made, checked by
# importing the plugin, torch and all) beside the builds; pytest waits for it.
bash scripts/lerobot_env.sh >build/lerobot-env.log 2>&1 &
lerobot_env_pid=$!

passed=0
failed=0
failures=()
count() { passed=$((passed + $1)); failed=$((failed + $2)); }
# took NAME STARTED: the step's time, in the log and in the closing list.
times=()
took() {
  echo "-- $1: $((SECONDS - $2)) s"
  times+=("$(printf '%5d s  %.60s' $((SECONDS - $2)) "$1")")
}

# outcome RC NAME: a step's outcome, counted as one check; named if it failed.
outcome() {
  if [ "$1" -eq 0 ]; then
    count 1 0
  else
    count 0 1
    failures+=("$2")
  fi
}

# run_step NAME COMMAND...: prints the name, runs the command (with set -e
# inside) and prints its time (also in step_s); returns its status.
run_step() {
  local name=$1
  shift
  printf '\n== %s\n' "$name"
  local started=$SECONDS
  # Not in an if: bash ignores set -e in a condition's subshell.
  (set -e; "$@")
  local rc=$?
  step_s=$((SECONDS - started))
  echo "-- $name: $step_s s"
  return $rc
}

# step NAME COMMAND...: runs the command, counts it as one check, and
# names it if it failed.
step() {
  run_step "$@"
  outcome $? "$1"
  times+=("$(printf '%5d s  %.60s' "$step_s" "$1")")
}

host_build() {
  cmake --preset host >/dev/null
  cmake --build --preset host
}

unit_tests() {
  # Side by side: the unit tests wait on nothing, and test_profile alone
  # takes a CPU a while.
  ctest --preset host -j "$(nproc)" | tee build/host/ctest.log
}

arm_m3_images() {
  cmake --preset arm >/dev/null
  cmake --build --preset arm
}

arm_m0_images() {
  cmake --preset arm-m0 >/dev/null
  cmake --build --preset arm-m0
}

arm_g0_images() {
  cmake --preset arm-g0 >/dev/null
  cmake --build --preset arm-g0
}

target_bench() {
  for cpu in m3 m0 m0p; do
    cmake --preset "target-bench-$cpu" >/dev/null
    cmake --build --preset "target-bench-$cpu" >/dev/null
  done
  # docs/benchmark.md's table is the one measured (--markdown prints it).
  python3 tests/bench/target/run_target_bench.py --check --doc docs/benchmark.md --json build/target-bench.json
}

# The planner's division and multiplication as each CPU runs them
# (tests/bench/target/check_arith.c): the M0's are assembly and its own.
target_arith() {
  for cpu in m3 m0; do
    cmake --preset "target-bench-$cpu" >/dev/null
    cmake --build --preset "target-bench-$cpu" --target check_arith.elf >/dev/null
    qemu-system-arm -M lm3s6965evb -cpu "cortex-$cpu" -nographic \
      -semihosting-config enable=on,target=native \
      -kernel "build/target-bench-$cpu/bench/check_arith.elf" 2>/dev/null
  done
}

fuzz_run() {
  cmake --preset fuzz >/dev/null
  # The whole preset, as docs/building.md builds it: a flag clang does not take
  # fails here, not for the next reader.
  cmake --build --preset fuzz
  local work
  work=$(mktemp -d)
  # New inputs go to the scratch folder; the committed seeds stay as they
  # are. Inputs up to 256 bytes: a dozen requests and as many clock, horn,
  # sensor, flash and power events.
  local started=$SECONDS
  if ! ./build/fuzz/tests/fuzz/fuzz_servo -runs="${FUZZ_RUNS:-200000}" -seed=1 -max_len=256 \
       -print_final_stats=1 "$work" tests/fuzz/corpus 2>"$work/log"; then
    tail -n 60 "$work/log" >&2
    echo "fuzzing found a failure (crash input saved in the working directory)" >&2
    rm -rf "$work"
    return 1
  fi
  grep -E '^(#[0-9]+\s+DONE|stat::number_of_executed_units|stat::average_exec_per_sec)' "$work/log"
  local units
  units=$(sed -nE 's/^stat::number_of_executed_units:\s+([0-9]+)/\1/p' "$work/log")
  rm -rf "$work"
  echo "fuzzing: $units inputs in $((SECONDS - started)) s"
  # The speed is a benchmark's figure (docs/fuzzing.md), not a gate: a
  # busy machine runs the same inputs, slower.
  if [ "${units:-0}" -lt "${FUZZ_RUNS:-200000}" ]; then
    echo "the fuzzer ran ${units:-0} inputs, not ${FUZZ_RUNS:-200000}" >&2
    return 1
  fi
}

step "host build: the simulator, the virtual boards' models, the unit tests (AddressSanitizer + UndefinedBehaviorSanitizer)" \
  host_build
step "layers: no include from a lower layer to a higher one, no circle (of includes, or of symbols in the host build's objects), no file over 400 lines outside the tests and generated files, no schema line over 120 characters, the build importing nothing from tools/" \
  python3 scripts/check_layers.py --objects build/host
step "registers: every definition of hal/ports against ST's SVD files (STM32F103xx, STM32F030, STM32G031)" \
  .venv/bin/python scripts/check_regs_svd.py
step "ARM images (STM32F103, and the QEMU board): budget and soft-float checks" arm_m3_images
step "Cortex-M0 image (STM32F030K6) and its bootloader: 4 KB RAM, 24 KB flash budget, 4 KB bootloader, soft-float" \
  arm_m0_images
step "Cortex-M0+ image (STM32G031K8) and its bootloader: 8 KB RAM, its slot, its 6 KB bootloader, soft-float" \
  arm_g0_images
# beside NAME COMMAND...: a step run beside pytest (below), as step runs
# one: its output in the job's log, its outcome and time in BESIDE_RESULTS.
BESIDE_LOG=build/beside-pytest.log
BESIDE_RESULTS=build/beside-pytest.results
beside() {
  run_step "$@"
  printf '%s\t%s\t%s\n' "$?" "$step_s" "$1" >>"$BESIDE_RESULTS"
}

# The steps that need nothing of pytest's and pytest nothing of theirs: one
# after another beside pytest's parallel pass, on the CPU its tests leave
# (most wait on simulated servos), and done before the wall_clock tests. The
# unit tests count each CTest program (below), not as one step.
beside_steps() {
  run_step "unit tests (host, AddressSanitizer + UndefinedBehaviorSanitizer)" unit_tests
  printf '%s\t%s\n' "$?" "$step_s" >build/host/ctest.rc
  beside "target benchmark: every packet and the control tick in Thumb instructions on the Cortex-M3, M0 and M0+ under QEMU, against the budgets and docs/benchmark.md" \
    target_bench
  beside "target arithmetic: the planner's 64-bit division and the run-time's division and multiplication on the Cortex-M3 and M0 under QEMU, against products" \
    target_arith
  beside "fuzzing the whole servo: ${FUZZ_RUNS:-200000} inputs (libFuzzer, ASan + UBSan, -O2)" fuzz_run
  beside "line coverage of motion, protection and the config store by the fuzz corpus (>= 90 %)" \
    bash scripts/fuzz_coverage.sh
}

# pytest counts each test. Most tests wait on simulated servos, not on the
# CPU: PYTEST_WORKERS (default 4) run side by side (pytest-xdist), each
# test file on one worker, so a file's shared simulator or QEMU board starts
# once, with the steps above beside them. Then the tests timed on the wall
# clock (marked wall_clock: the maker's SDK), alone.
if ! wait "$lerobot_env_pid"; then
  cat build/lerobot-env.log >&2
  echo "setup failed: scripts/lerobot_env.sh (pytest not run)" >&2
  exit 1
fi
cat build/lerobot-env.log
printf '\n== %s\n' "PC tool, simulator, maker's SDK and QEMU board tests (pytest), and beside it the unit tests, the target benchmark and arithmetic, the fuzz run and its coverage (their output after pytest's)"
started=$SECONDS
: >"$BESIDE_RESULTS"
rm -f build/host/ctest.log build/host/ctest.rc
pytest_both() {
  beside_steps >"$BESIDE_LOG" 2>&1 &
  local beside_pid=$!
  cd tools
  local rc=0
  ../.venv/bin/python -m pytest -q -p no:cacheprovider -n "${PYTEST_WORKERS:-4}" --dist loadfile \
    -m "not wall_clock" || rc=$?
  wait "$beside_pid"
  ../.venv/bin/python -m pytest -q -p no:cacheprovider -m wall_clock || rc=$?
  return $rc
}
pytest_both | tee build/pytest.log
tools_rc=${PIPESTATUS[0]}
took "pytest (with the steps beside it)" "$started"
cat "$BESIDE_LOG"
# Unit tests count each CTest program.
read -r unit_rc unit_s <build/host/ctest.rc || unit_rc=1
times+=("$(printf '%5d s  %.60s (beside pytest)' "${unit_s:-0}" "unit tests")")
unit_passed=$(sed -nE 's/.*tests passed, ([0-9]+) tests failed out of ([0-9]+).*/\2 \1/p' build/host/ctest.log 2>/dev/null)
if [ -n "$unit_passed" ]; then
  read -r total bad <<<"$unit_passed"
  count $((total - bad)) "$bad"
  [ "$bad" -eq 0 ] && [ "$unit_rc" -eq 0 ] || failures+=("unit tests")
else
  count 0 1
  failures+=("unit tests (did not build or run)")
fi
while IFS=$'\t' read -r rc secs name; do
  times+=("$(printf '%5d s  %.60s (beside pytest)' "$secs" "$name")")
  outcome "$rc" "$name"
done <"$BESIDE_RESULTS"
if [ "$(wc -l <"$BESIDE_RESULTS")" -ne 4 ]; then
  count 0 1
  failures+=("the steps beside pytest did not all finish ($BESIDE_LOG)")
fi
# Each run's closing line: "N failed, N passed, ... in S s".
totals=$(grep -E '^(=+ )?[0-9]+ [a-z]+.* in [0-9.]+s' build/pytest.log)
tools_passed=$(grep -oE '[0-9]+ passed' <<<"$totals" | awk '{n += $1} END {print n + 0}')
tools_failed=$(grep -oE '[0-9]+ (failed|errors?)\b' <<<"$totals" | awk '{n += $1} END {print n + 0}')
count "${tools_passed:-0}" "${tools_failed:-0}"
if [ "$tools_rc" -ne 0 ]; then
  failures+=("pytest (exit $tools_rc)")
  [ "${tools_failed:-0}" -gt 0 ] || count 0 1
fi


echo
printf 'step times:\n'
printf '  %s\n' "${times[@]}"
echo "total: $SECONDS s"
for f in "${failures[@]}"; do
  echo "FAILED: $f"
done
echo "summary: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
