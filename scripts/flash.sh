#!/usr/bin/env bash
# Flashes the reference board through an ST-LINK: `scripts/flash.sh openocd`
# (default) or `scripts/flash.sh st-flash`. Builds the image first.
set -euo pipefail
cd "$(dirname "$0")/.."
tool=${1:-openocd}
elf=build/arm/firmware/boards/stm32f103/servo_stm32f103.elf
bin=build/arm/firmware/boards/stm32f103/servo_stm32f103.bin

need() {
  command -v "$1" >/dev/null || {
    echo "flash: $1 is not installed; on Debian: sudo apt-get install $2" >&2
    exit 1
  }
}

cmake --preset arm >/dev/null
cmake --build --preset arm --target servo_stm32f103.elf
case "$tool" in
  openocd)
    need openocd openocd
    openocd -f interface/stlink.cfg -f target/stm32f1x.cfg \
      -c "program $elf verify reset exit"
    ;;
  st-flash)
    need st-flash stlink-tools
    st-flash --reset write "$bin" 0x08000000
    ;;
  *)
    echo "usage: scripts/flash.sh [openocd|st-flash]" >&2
    exit 2
    ;;
esac
