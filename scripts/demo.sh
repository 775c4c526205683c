#!/usr/bin/env bash
# The demo: builds everything, starts a simulated servo running the firmware,
# and drives it with servoctl: scan, info, a velocity-profile move, and a
# recorded move plotted against its plan (the PNG's path is printed).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

echo; echo "== building: host (simulator, tests) and the three boards' images"
cmake --preset host >/dev/null
cmake --build --preset host >/dev/null
# The three boards' images (arm-g0 adds about 8 s from scratch on 2 cores), so
# `servoctl sim --board stm32f103|stm32f030k6|stm32g031k8` works after the demo.
for preset in arm arm-m0 arm-g0; do
    cmake --preset "$preset" >/dev/null
    cmake --build --preset "$preset" | grep -E '^image ' || true
done

out=demo-output
mkdir -p "$out"
state=$(mktemp -d)
port=$(.venv/bin/python -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
# A new servo: ID 0 at 115200 baud, as it comes from the factory (README.md).
./build/host/firmware/boards/host_sim/servo_sim --id 0 --tcp "$port" --state "$state" >"$out/sim.log" 2>&1 &
sim=$!
trap 'kill $sim 2>/dev/null || true; rm -rf "$state"' EXIT
for _ in $(seq 100); do grep -q ready "$out/sim.log" 2>/dev/null && break; sleep 0.05; done
grep -q ready "$out/sim.log" || { cat "$out/sim.log" >&2; echo "demo: the simulator did not start" >&2; exit 1; }
export SERVOCTL_PORT="socket://127.0.0.1:$port"
servoctl=.venv/bin/servoctl
echo; echo "== a simulated servo on $SERVOCTL_PORT"

step() { echo; echo "\$ servoctl $*"; "$servoctl" "$@"; }
step scan --last 10
step info 0
step config set 0 soft_start_on 0
step move 0 100 --velocity 300 --acc 100 --dec 200 --wait
step record 0 -45 --velocity 200 --acc 100 --dec 100 --out "$out/record"
echo
echo "demo: done; the recorded move is plotted in $(pwd)/$out/record.png"
