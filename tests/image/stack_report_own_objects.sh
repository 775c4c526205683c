#!/bin/sh
# cmake/stack-report.py must take the call graphs of the objects the image
# links, not of every object in the build: a build holds the other board
# family's port too, with the same handler names. Two ports define
# USART1_IRQHandler; port B's calls a function with a 1200-byte frame; the
# image links port A. The report must show port A's handler, and fail on
# port B's when the image links that one instead.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The reference board's application memory map, as the build makes it.
arm-none-eabi-gcc -E -P -x c -I "$root/firmware" -DSERVO_BOARD_H='"boards/stm32f103/board.h"' "$root/hal/ports/stm32_common/linker/app.ld.in" \
  -o "$tmp/app.ld" || exit 1
cc() { arm-none-eabi-gcc -mcpu=cortex-m3 -mthumb -Os -ffunction-sections -fcallgraph-info=su "$@"; }
for port in a b; do
  dir="$tmp/build/port_$port/CMakeFiles/port_$port.dir"
  mkdir -p "$dir"
  def=$([ "$port" = b ] && echo -DPORT_B || echo -DPORT_A)
  cc $def -c "$root/tests/image/stack_ports/port.c" -o "$dir/port.c.obj" || exit 1
  arm-none-eabi-ar rcs "$tmp/build/port_$port/libport_$port.a" "$dir/port.c.obj"
done
mkdir -p "$tmp/build/img"
cc -c "$root/tests/image/stack_ports/main.c" -o "$tmp/build/img/main.c.obj" || exit 1
link() {
  (cd "$tmp/build" && arm-none-eabi-gcc -mcpu=cortex-m3 -mthumb -nostartfiles --specs=nano.specs \
    --specs=nosys.specs -L "$root/hal/ports/stm32_common/linker" -T "$tmp/app.ld" \
    -Wl,--gc-sections -Wl,-Map=img/img.map img/main.c.obj "port_$1/libport_$1.a" -o img/img.elf) || exit 1
}
fail=0
link a
out=$(python3 "$root/cmake/stack-report.py" "$tmp/build/img/img.elf" "$tmp/build" 2>&1) ||
  { echo "image with port A rejected: $out"; fail=1; }
echo "$out" | grep -q "USART1_IRQHandler .* B  USART1_IRQHandler > drain$" ||
  { echo "handler not found: $out"; fail=1; }
echo "$out" | grep -Eq "USART1_IRQHandler +([0-9]|[0-9][0-9]) B" ||
  { echo "port B's handler counted for an image that links port A: $out"; fail=1; }
link b
if python3 "$root/cmake/stack-report.py" "$tmp/build/img/img.elf" "$tmp/build" >/dev/null 2>&1; then
  echo "image with port B's 1200-byte handler accepted"; fail=1
fi
[ "$fail" = 0 ] && echo "stack report: the image's own objects only"
exit "$fail"
