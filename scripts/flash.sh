#!/usr/bin/env bash
# Flashes the reference board through an ST-LINK: `scripts/flash.sh openocd`
# (default) or `scripts/flash.sh st-flash`. Builds the images first: the
# bootloader at the start of flash, the application's update image in its
# slot (0x08001000). Later updates go over the bus (servoctl update).
set -euo pipefail
cd "$(dirname "$0")/.."
tool=${1:-openocd}
dir=build/arm/firmware/boards/stm32f103
boot=$dir/servo_stm32f103_boot.elf
boot_bin=$dir/servo_stm32f103_boot.bin
img=$dir/servo_stm32f103.img
slot=0x08001000

need() {
  command -v "$1" >/dev/null || {
    echo "flash: $1 is not installed; on Debian: sudo apt-get install $2" >&2
    exit 1
  }
}

cmake --preset arm >/dev/null
cmake --build --preset arm --target servo_stm32f103_boot.elf servo_stm32f103.elf
case "$tool" in
  openocd)
    need openocd openocd
    openocd -f interface/stlink.cfg -f target/stm32f1x.cfg \
      -c "program $boot verify" -c "program $img $slot verify reset exit"
    ;;
  st-flash)
    need st-flash stlink-tools
    st-flash write "$boot_bin" 0x08000000
    st-flash --reset write "$img" "$slot"
    ;;
  *)
    echo "usage: scripts/flash.sh [openocd|st-flash]" >&2
    exit 2
    ;;
esac
