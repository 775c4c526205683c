#!/usr/bin/env bash
# Runs the pytest suite (simulator, maker's SDK, QEMU board) RUNS times while
# BUSY processes spin on the CPUs, as on a shared CI machine. Timing-dependent
# tests that pass on an idle PC and fail here are bugs. Not part of the test
# command: it takes RUNS x about 1100 s with 8 spinners on 2 cores. Brings the
# host and ARM builds up to date first (configured by bash scripts/test.sh).
#   bash scripts/stress.sh [RUNS] [BUSY]      defaults: 5 runs, 2 x nproc busy
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-5}
busy=${2:-$((2 * $(nproc)))}
logs=build/stress
mkdir -p "$logs"

# The suite runs the builds in build/: bring them up to date first, or a
# stale simulator fails tests that have nothing to do with load.
for preset in host arm; do
    if [ ! -d "build/$preset" ]; then
        echo "stress: no build/$preset: run 'bash scripts/test.sh' once first" >&2
        exit 2
    fi
    cmake --build --preset "$preset" >/dev/null || { echo "stress: the $preset build failed" >&2; exit 2; }
done

pids=()
stop_busy() { kill "${pids[@]}" 2>/dev/null || true; }
trap stop_busy EXIT
for _ in $(seq "$busy"); do
    (while :; do :; done) &
    pids+=($!)
done

failed=0
for run in $(seq "$runs"); do
    log="$logs/run-$run.log"
    # As scripts/test.sh runs it: on workers, then the wall-clock tests alone.
    if (cd tools && ../.venv/bin/python -m pytest -q -p no:cacheprovider -n "${PYTEST_WORKERS:-4}" \
          --dist loadfile -m "not wall_clock" &&
        ../.venv/bin/python -m pytest -q -p no:cacheprovider -m wall_clock) >"$log" 2>&1; then
        echo "run $run/$runs under $busy busy processes: $(tail -1 "$log")"
    else
        failed=$((failed + 1))
        echo "run $run/$runs under $busy busy processes: FAILED, see $log"
        grep -E '^(FAILED|ERROR) ' "$log" || true
    fi
done
echo "stress: $((runs - failed)) of $runs runs passed"
[ "$failed" -eq 0 ]
