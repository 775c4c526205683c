#!/usr/bin/env bash
# Flash and RAM of each firmware module in the STM32F103 image, the
# Cortex-M0 (STM32F030K6) image and the Cortex-M0+ (STM32G031K8) image
# (what the linker kept, from its map), then each board's application and
# bootloader against the limits the build checks them against (its board.h:
# the slot less the update image's 256-byte header, the bootloader's
# pages, the part's RAM).
set -euo pipefail
cd "$(dirname "$0")/.."
for preset in arm arm-m0 arm-g0; do
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" >/dev/null
done
fact() { awk -v n="BOARD_$2" '$1 == "#define" && $2 == n { print $3 }' "firmware/boards/$1/board.h"; }
for board in "arm stm32f103 STM32F103 (Cortex-M3)" "arm-m0 stm32f030k6 STM32F030K6 (Cortex-M0)" \
             "arm-g0 stm32g031k8 STM32G031K8 (Cortex-M0+)"; do
  read -r preset name title <<<"$board"
  echo "$title:"
  python3 cmake/footprint.py "build/$preset/firmware/boards/$name/servo_$name.map"
  echo
done
echo "Applications and bootloaders, against their limits:"
for board in arm:stm32f103 arm-m0:stm32f030k6 arm-g0:stm32g031k8; do
  preset=${board%%:*} name=${board#*:}
  ram=$(fact "$name" RAM_SIZE)
  sh cmake/check-image.sh "build/$preset/firmware/boards/$name/servo_$name.elf" \
    $(( $(fact "$name" SLOT_PAGES) * $(fact "$name" FLASH_PAGE) - 256 )) "$ram"
  sh cmake/check-image.sh "build/$preset/firmware/boards/$name/servo_${name}_boot.elf" "$(fact "$name" BOOT_SIZE)" "$ram"
done
