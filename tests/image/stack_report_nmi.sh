#!/bin/sh
# cmake/stack-report.py must count the NMI on top of the deepest interrupt
# handler (it preempts them), with what its naked handler calls from
# assembly, which no call graph shows: a 128-byte frame there is counted.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
arm-none-eabi-gcc -E -P -x c -I "$root/firmware" -DSERVO_BOARD_H='"boards/stm32g031k8/board.h"' \
  "$root/hal/ports/stm32_common/linker/app.ld.in" -o "$tmp/app.ld" || exit 1
cc() { arm-none-eabi-gcc -mcpu=cortex-m0plus -mthumb -Os -ffunction-sections "$@"; }
mkdir -p "$tmp/build/img"
cc -fcallgraph-info=su -c "$root/tests/image/stack_nmi/nmi.c" -o "$tmp/build/img/nmi.c.obj" || exit 1
(cd "$tmp/build" && cc -nostartfiles --specs=nano.specs --specs=nosys.specs \
  -L "$root/hal/ports/stm32_common/linker" -T "$tmp/app.ld" -Wl,--gc-sections -Wl,-Map=img/img.map \
  img/nmi.c.obj -o img/img.elf) || exit 1
out=$(python3 "$root/cmake/stack-report.py" "$tmp/build/img/img.elf" "$tmp/build" 2>&1)
# main's frame + 32 + USART1's 64-odd + the NMI's 8 + 128-odd + 32
echo "$out" | grep -Eq "USART1_IRQHandler [0-9]+ \+ NMI with its frame (1[6-9][0-9]|2[0-9][0-9])\)" ||
  { echo "the NMI's frames were not counted on top of the handler's: $out"; exit 1; }
