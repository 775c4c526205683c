#!/usr/bin/env bash
# Runs the pytest suite (or the pytest arguments given, from tools/) with
# every figure its tests judge recorded (tools/tests/figure_record.py):
# once with the numerical kernels this machine picks, once with those
# another x86-64 machine may pick, and, with AGAIN=1, once more as the first
# (what moves between those two moves from run to run, not with the kernel).
# Then scripts/figures_compare.py names every figure that moved and every
# test whose outcome changed (exit 1). docs/testing.md, "On any machine".
#
#   bash scripts/other_kernels.sh                       # the suite, but wall_clock
#   bash scripts/other_kernels.sh tests/integration/test_identify.py
#
# "Another machine's kernels": tools/tests/kernels.py says which, and why.
# OUT (default build/kernels) keeps each run's records and the comparison.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
bash scripts/lerobot_env.sh >/dev/null
for preset in host arm arm-m0; do  # what the suite runs: servo_sim, the boards' images
  cmake --preset $preset >/dev/null && cmake --build --preset $preset >/dev/null
done
out=${OUT:-build/kernels}
rm -rf "$out"
mkdir -p "$out"
out=$(cd "$out" && pwd)

mapfile -t other_env < <(cd tools && ../.venv/bin/python -m tests.kernels)
[ ${#other_env[@]} -gt 0 ] || { echo "other_kernels: no other kernels to force on $(uname -m)" >&2; exit 2; }

if [ $# -eq 0 ]; then
  set -- -n "${PYTEST_WORKERS:-4}" --dist loadfile -m "not wall_clock"
fi
# run NAME [VAR=VALUE...]: the suite with its figures recorded in $out/NAME.
run() {
  local name=$1
  shift
  echo "== $name${*:+: $*}"
  (cd tools && env "$@" SERVO_FIGURES="$out/$name" PYTHONDONTWRITEBYTECODE=1 \
     ../.venv/bin/python -m pytest -q -p no:cacheprovider -p tests.figure_record \
     -o enable_assertion_pass_hook=true "${pytest_args[@]}") | tee "$out/$name.log" | tail -n 3 || true
}
pytest_args=("$@")
run base
run other "${other_env[@]}"
again=()
if [ "${AGAIN:-0}" = 1 ]; then
  run again
  again=(--again "$out/again")
fi
.venv/bin/python scripts/figures_compare.py "$out/base" "$out/other" "${again[@]}" | tee "$out/comparison.txt"
