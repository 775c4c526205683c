#!/usr/bin/env bash
# Installs what building and testing need, only what is missing: Debian
# packages (as root, or through sudo), the project's Python virtual
# environment in .venv. Safe to run again. (The LeRobot plugin's heavy
# environment is the test command's: scripts/lerobot_env.sh.)
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(cmake ninja-build gcc g++ pkg-config libcmocka-dev clang libclang-rt-14-dev
          gcc-arm-none-eabi libnewlib-arm-none-eabi valgrind python3-venv qemu-system-arm
          chromium chromium-driver)  # chromium: servoctl ui's browser tests

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  if [ "$(id -u)" -eq 0 ]; then SUDO=(); elif command -v sudo >/dev/null; then SUDO=(sudo); else
    echo "setup: missing packages ${missing[*]} and no root or sudo to install them" >&2
    exit 1
  fi
  "${SUDO[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${SUDO[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi

if [ ! -x .venv/bin/python ]; then
  echo "setup: creating .venv"
  python3 -m venv .venv
fi
# The versions in tools/constraints.txt, those the suite was measured with;
# --unpinned takes the newest the requirements allow (to renew the pins).
pins=(-c tools/constraints.txt)
[ "${1:-}" = "--unpinned" ] && pins=()
if ! .venv/bin/python -m pip install -q --disable-pip-version-check "${pins[@]}" -r tools/requirements.txt \
     || ! .venv/bin/python -m pip install -q --disable-pip-version-check "${pins[@]}" -e tools; then
  echo "setup: pip could not install tools/requirements.txt or the servoctl package" \
       "(within tools/constraints.txt's versions)" >&2
  exit 1
fi
echo "setup: ready"
