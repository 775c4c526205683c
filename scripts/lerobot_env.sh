#!/usr/bin/env bash
# The maker's LeRobot plugin in its own virtual environment
# (tools/tests/lerobot/test_lerobot.py drives a simulated arm with it).
# LeRobot pulls in torch, and PyPI's Linux torch wheel pulls in NVIDIA's CUDA
# libraries: 4.1 GB of wheels, 8.3 GB installed, about 7 minutes. So it stays
# out of the demo's .venv, and it is made once a machine, not once a clone:
# it lives in the user's cache under a name drawn from its pinned packages,
# and .venv-lerobot in the clone is a link to it. Run again, it does nothing.
# LEROBOT_ENV=0 skips it (the test then says why it skips); LEROBOT_VENV=DIR
# puts the environment elsewhere.
set -euo pipefail
cd "$(dirname "$0")/.."
PACKAGES=("lerobot==0.4.4" "lerobot-robot-viola==0.0.4" "lerobot-motor-starai==0.0.7"
          "fashionstar-uart-sdk==1.3.12")
if [ "${LEROBOT_ENV:-1}" = "0" ]; then
  echo "lerobot env: skipped (LEROBOT_ENV=0)"
  exit 0
fi
pins=$(printf '%s\n' "${PACKAGES[@]}" "$(python3 -V)" | sha256sum | cut -c1-12)
VENV=${LEROBOT_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/servo-firmware/lerobot-$pins}
ready() { [ -x "$1/bin/python" ] && "$1/bin/python" -c "import lerobot_robot_viola.starai_viola" 2>/dev/null; }
if ! ready "$VENV"; then
  echo "lerobot env: creating $VENV (${PACKAGES[*]}; several GB, once a machine)"
  mkdir -p "$(dirname "$VENV")"
  [ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
  # An install cut short is finished by the next run: ready() fails.
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check "${PACKAGES[@]}"
  ready "$VENV" || { echo "lerobot env: $VENV cannot import the plugin" >&2; exit 1; }
  echo "lerobot env: ready"
fi
# The clone's name for it; an older clone's own directory is left alone.
if [ -L .venv-lerobot ] || [ ! -e .venv-lerobot ]; then
  ln -sfn "$VENV" .venv-lerobot
fi
