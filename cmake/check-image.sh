#!/bin/sh
# Prints the image's flash and RAM use and fails when it exceeds its limits
# or links any soft-float helper: firmware code is fixed point.
#   check-image.sh ELF [FLASH_LIMIT [RAM_LIMIT]]
# The application's limits default to 32 KB / 8 KB, and it is measured
# against the small part's budget of 24 KB / 4 KB (the 4 KB bootloader, the
# application, the 2 KB store and 2 KB spare fit a 32 KB part with 4 KB of
# RAM): a board whose part is that small passes the budget as its limits
# (the Cortex-M0 board: board.cmake). A board with more RAM may spend it
# (the reference board's 4 KB receive ring), and the line says it would not
# fit the small part. The bootloader: check-image.sh ELF 4096 [RAM_LIMIT],
# its 4 KB (and a small part's RAM).
set -eu
elf=$1
SIZE=${SIZE:-arm-none-eabi-size}
NM=${NM:-arm-none-eabi-nm}
FLASH_LIMIT=${2:-32768}; RAM_LIMIT=${3:-8192}; FLASH_BUDGET=24576; RAM_BUDGET=4096
if [ "$FLASH_LIMIT" -lt "$FLASH_BUDGET" ]; then FLASH_BUDGET=$FLASH_LIMIT; fi
if [ "$RAM_LIMIT" -lt "$RAM_BUDGET" ]; then RAM_BUDGET=$RAM_LIMIT; fi

sizes=$($SIZE -A "$elf")
section() { echo "$sizes" | awk -v s="$1" '$1 == s { print $2; f=1 } END { if (!f) print 0 }'; }
flash=$(( $(section .isr_vector) + $(section .text) + $(section .ARM.exidx) + $(section .data) ))
# .ram_vectors: a Cortex-M0 image's vector table, copied to RAM.
ram=$(( $(section .ram_vectors) + $(section .data) + $(section .bss) + $(section .stack) ))
verdict() { if [ "$1" -le "$2" ]; then echo "met"; else echo "NOT MET"; fi; }
echo "image: flash $flash B of $FLASH_LIMIT (budget $FLASH_BUDGET: $(verdict $flash $FLASH_BUDGET)), RAM $ram B of $RAM_LIMIT (budget $RAM_BUDGET: $(verdict $ram $RAM_BUDGET); vectors $(section .ram_vectors) + .data $(section .data) + .bss $(section .bss) + stack $(section .stack))"

status=0
if [ "$flash" -gt "$FLASH_LIMIT" ]; then echo "error: flash $flash B exceeds $FLASH_LIMIT B" >&2; status=1; fi
if [ "$ram" -gt "$RAM_LIMIT" ]; then echo "error: RAM $ram B exceeds $RAM_LIMIT B" >&2; status=1; fi
soft=$($NM "$elf" | awk '{ print $NF }' |
       grep -E '^__aeabi_(f|d|[ui]2[fd]|[fd]2)|^__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord)[sdt]f[23]$|^__(fix|float|extend|trunc)[a-z]*[sdt]f' || true)
if [ -n "$soft" ]; then
  echo "error: soft-float helpers linked (firmware code must be fixed point):" >&2
  echo "$soft" >&2
  status=1
fi
exit $status
