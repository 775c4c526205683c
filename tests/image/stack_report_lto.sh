#!/bin/sh
# cmake/stack-report.py must count what the link-time optimisation compiled:
# an object built for it holds no code, its own call graph says nothing, and
# the main loop's frames are in the link's partitions' call graphs. Linked
# with them, a 512-byte frame in servo_poll is counted; linked without them,
# the report must fail, not pass an image it cannot measure.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
arm-none-eabi-gcc -E -P -x c -I "$root/firmware" -DSERVO_BOARD_H='"boards/stm32f103/board.h"' \
  "$root/hal/ports/stm32_common/linker/app.ld.in" -o "$tmp/app.ld" || exit 1
cc() { arm-none-eabi-gcc -mcpu=cortex-m3 -mthumb -Os -ffunction-sections -flto "$@"; }
mkdir -p "$tmp/build/img"
cc -fcallgraph-info=su -c "$root/tests/image/stack_lto/loop.c" -o "$tmp/build/img/loop.c.obj" || exit 1
link() {
  rm -f "$tmp"/build/img/img.elf.ltrans*
  (cd "$tmp/build" && cc "$@" -nostartfiles --specs=nano.specs --specs=nosys.specs \
    -L "$root/hal/ports/stm32_common/linker" -T "$tmp/app.ld" -Wl,--gc-sections -Wl,-Map=img/img.map \
    img/loop.c.obj -o img/img.elf) || exit 1
}
fail=0
link -fcallgraph-info=su
out=$(python3 "$root/cmake/stack-report.py" "$tmp/build/img/img.elf" "$tmp/build" 2>&1)
echo "$out" | grep -Eq "main +(5[1-9][0-9]|[6-9][0-9][0-9]) B  main > servo_poll" ||
  { echo "the main loop's 512-byte frame was not counted: $out"; fail=1; }
link
if out=$(python3 "$root/cmake/stack-report.py" "$tmp/build/img/img.elf" "$tmp/build" 2>&1); then
  echo "an image whose main loop no call graph describes was passed: $out"; fail=1
fi
exit $fail
