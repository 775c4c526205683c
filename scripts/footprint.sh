#!/usr/bin/env bash
# Flash and RAM of each firmware module in the STM32F103 image (what the
# linker kept, from its map), and the image's totals.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset arm >/dev/null
cmake --build --preset arm >/dev/null
exec python3 cmake/footprint.py build/arm/firmware/boards/stm32f103/servo_stm32f103.map
