#!/usr/bin/env bash
# servoctl_arm against the maker's LeRobot plugin on the same simulated arm
# (7 servos, IDs 0-6, 1 Mbaud): a 30 Hz follower loop of a 0.5 Hz +-45 deg
# sine through LeRobot's robot interface; prints docs/lerobot.md's table.
# Needs servo_sim (cmake --preset host && cmake --build --preset host) and
# the LeRobot environment (scripts/lerobot_env.sh, made if missing); builds
# the optimised simulator the real-time runs use (the sim preset).
# Arguments go to tools/lerobot_plugins/compare.py (--only ours|maker, --json FILE).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset sim >/dev/null && cmake --build --preset sim >/dev/null
exec bash scripts/lerobot_run.sh tools/lerobot_plugins/compare.py "$@"
