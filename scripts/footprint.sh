#!/usr/bin/env bash
# Flash and RAM of each firmware module in the STM32F103 image and in the
# Cortex-M0 (STM32F030K6) image (what the linker kept, from its map), and
# each image's totals; then both boards' bootloaders.
set -euo pipefail
cd "$(dirname "$0")/.."
for preset in arm arm-m0; do
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" >/dev/null
done
echo "STM32F103 (Cortex-M3):"
python3 cmake/footprint.py build/arm/firmware/boards/stm32f103/servo_stm32f103.map
echo
echo "STM32F030K6 (Cortex-M0):"
python3 cmake/footprint.py build/arm-m0/firmware/boards/stm32f030k6/servo_stm32f030k6.map
echo
echo "Bootloaders (4 KB each, and each part's RAM: 20 KB, 4 KB):"
sh cmake/check-image.sh build/arm/firmware/boards/stm32f103/servo_stm32f103_boot.elf 4096 20480
sh cmake/check-image.sh build/arm-m0/firmware/boards/stm32f030k6/servo_stm32f030k6_boot.elf 4096 4096
