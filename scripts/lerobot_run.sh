#!/usr/bin/env bash
# Runs Python in the LeRobot environment (.venv-lerobot, scripts/lerobot_env.sh)
# with this checkout's LeRobot plugins (tools/lerobot_plugins: servoctl_arm,
# servoctl_leader) installed by pip as LeRobot finds them, and servoctl
# from tools/ (with its schema and image packages):
#     bash scripts/lerobot_run.sh -m lerobot.scripts.lerobot_teleoperate ...
# The plugins go to build/lerobot-plugins/<hash of their files>, installed
# once for each version of them, so the environment shared by every clone
# is left as it is, and runs side by side each find theirs whole.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PY="$ROOT/.venv-lerobot/bin/python"
[ -x "$PY" ] || bash "$ROOT/scripts/lerobot_env.sh" >&2
PLUGINS=(lerobot_robot_servoctl lerobot_teleoperator_servoctl)
hash=$(cd "$ROOT/tools/lerobot_plugins" && find "${PLUGINS[@]}" -name build -prune -o -name '*.egg-info' -prune \
         -o -type f \( -name '*.py' -o -name pyproject.toml \) -print | LC_ALL=C sort | xargs sha256sum \
       | sha256sum | cut -c1-12)
TARGET="$ROOT/build/lerobot-plugins/$hash"
if [ ! -d "$TARGET" ]; then
  mkdir -p "$ROOT/build/lerobot-plugins"
  # setuptools builds in the source tree, and would pack a stale build/ along.
  for p in "${PLUGINS[@]}"; do rm -rf "$ROOT/tools/lerobot_plugins/$p/build"; done
  NEW=$(mktemp -d "$ROOT/build/lerobot-plugins/.new.XXXXXX")
  "$PY" -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation --no-compile \
    --target "$NEW" "${PLUGINS[@]/#/$ROOT/tools/lerobot_plugins/}" >&2
  # A run beside this one may have put it there first: its copy is as good.
  mv -T "$NEW" "$TARGET" 2>/dev/null || rm -rf "$NEW"
fi
# servoctl's packages where `pip install -e tools` finds them (tools/pyproject.toml's
# package-dir): the schema in protocol/, the update image's maker in bootloader/.
export PYTHONPATH="$TARGET:$ROOT/tools:$ROOT/protocol:$ROOT/bootloader${PYTHONPATH:+:$PYTHONPATH}"
exec "$PY" "$@"
