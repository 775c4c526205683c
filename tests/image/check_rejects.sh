#!/bin/sh
# cmake/check-image.sh must reject an image with soft-float helpers and one
# over the RAM budget, and accept a clean one: a check that cannot fail
# proves nothing.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The reference board's application memory map, as the build makes it.
arm-none-eabi-gcc -E -P -x c -I "$root/firmware" -DSERVO_BOARD_H='"boards/stm32f103/board.h"' "$root/hal/ports/stm32_common/linker/app.ld.in" \
  -o "$tmp/app.ld" || exit 1
build() {
  arm-none-eabi-gcc -mcpu=cortex-m3 -mthumb -Os -nostartfiles --specs=nano.specs \
    --specs=nosys.specs -L "$root/hal/ports/stm32_common/linker" -T "$tmp/app.ld" "$@" \
    "$root/tests/image/probe.c" -o "$tmp/probe.elf" || exit 1
}
fail=0
build
sh "$root/cmake/check-image.sh" "$tmp/probe.elf" >"$tmp/out" 2>&1 || { echo "clean image rejected"; fail=1; }
grep -q "^image probe.elf: " "$tmp/out" || { echo "the image is not named"; fail=1; }
build -DUSE_FLOAT
if sh "$root/cmake/check-image.sh" "$tmp/probe.elf" 2>"$tmp/err" >/dev/null; then
  echo "soft-float image accepted"; fail=1
fi
grep -q "__aeabi_f" "$tmp/err" || { echo "soft-float helper not named"; fail=1; }
build -DBIG_RAM
if sh "$root/cmake/check-image.sh" "$tmp/probe.elf" 2>"$tmp/err" >/dev/null; then
  echo "image over the RAM budget accepted"; fail=1
fi
grep -q "RAM .* exceeds 8192" "$tmp/err" || { echo "RAM overrun not reported"; fail=1; }
build
if sh "$root/cmake/check-image.sh" "$tmp/probe.elf" 8 2>"$tmp/err" >/dev/null; then
  echo "image over a bootloader-style flash budget accepted"; fail=1
fi
grep -q "flash .* exceeds 8 B" "$tmp/err" || { echo "flash overrun not reported"; fail=1; }
if sh "$root/cmake/check-image.sh" "$tmp/probe.elf" 32768 64 2>"$tmp/err" >/dev/null; then
  echo "image over a board's RAM limit (the Cortex-M0 board's style) accepted"; fail=1
fi
grep -q "RAM .* exceeds 64 B" "$tmp/err" || { echo "board RAM overrun not reported"; fail=1; }
[ $fail -eq 0 ] && echo "check-image: rejects soft float, RAM and flash overruns, accepts a clean image"
exit $fail
