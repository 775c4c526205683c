#!/usr/bin/env bash
# servoctl at the wire's speed: Sync Monitor rounds of 16 simulated servos
# and the update of a 20 KB image, at 1 000 000 and 115 200 baud, each
# against the limit the packets' sizes (and the flash) set, the host behind
# the simulated USB adapter (the default) and on the raw link (each byte as it
# ends on the wire; docs/simulator.md). Times are the simulator's clock. Not
# part of the test command (about two minutes).
#   bash scripts/bus_bench.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh >/dev/null
cmake --preset host >/dev/null
cmake --build --preset host --target servo_sim >/dev/null
exec .venv/bin/python - <<'PY'
import tempfile

from servoctl import registers
from servoctl.cli import main
from servoctl.servo import Servo
from servoctl.sim import Simulator

ids = list(range(1, 17))
for link, baud in [(link, baud) for link in ("usb", "raw") for baud in (1000000, 115200)]:
    if baud == 1000000:
        print(f"host link {link}:", flush=True)
    with Simulator(ids=ids, state_dir=tempfile.mkdtemp(prefix="bus-bench-"), host_link=link) as sim:
        code = {rate: c for c, rate in registers.BAUD_RATES.items()}[baud]
        with sim.bus() as bus:
            for i in ids:
                Servo(bus, i).write("baud", code)  # answered at 115200, then it switches
        sim.sleep(0.05)
        # socket:// carries no rate: servoctl sets the simulator's (hostbaud).
        argv = ["--port", sim.url, "--sim-control", str(sim.control_port), "--baud", str(baud),
                "bench", "--ids", *map(str, ids),
                "--update-id", "1"]
        if main(argv, clock=sim.clock_s) != 0:
            raise SystemExit(1)
PY
