#!/usr/bin/env bash
# Runs Python in the LeRobot environment (.venv-lerobot, scripts/lerobot_env.sh)
# with this checkout's LeRobot plugins (tools/lerobot_plugins: servoctl_arm,
# servoctl_leader) installed by pip as LeRobot finds them, and servoctl
# from tools/:
#     bash scripts/lerobot_run.sh -m lerobot.scripts.lerobot_teleoperate ...
# The plugins go to build/lerobot-plugins, made anew each run from the
# checkout, so the environment shared by every clone is left as it is.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY="$ROOT/.venv-lerobot/bin/python"
[ -x "$PY" ] || bash "$ROOT/scripts/lerobot_env.sh"
TARGET="$ROOT/build/lerobot-plugins"
NEW=$(mktemp -d "$ROOT/build/.lerobot-plugins.XXXXXX" 2>/dev/null || { mkdir -p "$ROOT/build"; mktemp -d "$ROOT/build/.lerobot-plugins.XXXXXX"; })
"$PY" -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation --no-compile \
  --target "$NEW" "$ROOT/tools/lerobot_plugins/lerobot_robot_servoctl" \
  "$ROOT/tools/lerobot_plugins/lerobot_teleoperator_servoctl" >&2
rm -rf "$TARGET"
mv "$NEW" "$TARGET"
export PYTHONPATH="$TARGET:$ROOT/tools:$ROOT/protocol${PYTHONPATH:+:$PYTHONPATH}"
exec "$PY" "$@"
