#!/usr/bin/env bash
# The maker's LeRobot plugin in its own virtual environment, .venv-lerobot
# (tools/tests/lerobot/test_lerobot.py drives a simulated arm with it).
# LeRobot pulls in torch, and PyPI's Linux torch wheel pulls in NVIDIA's CUDA
# libraries: 4.1 GB of wheels, 8.3 GB installed (7 minutes on a loaded 2-core
# machine with a fast mirror), so it stays out of
# the demo's .venv. Made once; run again, it does nothing. LEROBOT_ENV=0
# skips it (the test then says why it skips).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=.venv-lerobot
PACKAGES=("lerobot==0.4.4" "lerobot-robot-viola==0.0.4" "lerobot-motor-starai==0.0.7"
          "fashionstar-uart-sdk==1.3.12")
if [ "${LEROBOT_ENV:-1}" = "0" ]; then
  echo "lerobot env: skipped (LEROBOT_ENV=0)"
  exit 0
fi
if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import lerobot_robot_viola.starai_viola" 2>/dev/null; then
  exit 0
fi
echo "lerobot env: creating $VENV (${PACKAGES[*]}; several GB, once)"
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
# An install cut short is finished by the next run: the check above fails.
"$VENV/bin/python" -m pip install -q --disable-pip-version-check "${PACKAGES[@]}"
echo "lerobot env: ready"
