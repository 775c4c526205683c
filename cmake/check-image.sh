#!/bin/sh
# Prints the image's flash and RAM use and fails when it exceeds the budget
# (the application: 32 KB flash, 8 KB RAM, the goal we track 16 KB / 4 KB;
# the bootloader: check-image.sh ELF 4096, its 4 KB) or links any
# soft-float helper: firmware code is fixed point.
set -eu
elf=$1
SIZE=${SIZE:-arm-none-eabi-size}
NM=${NM:-arm-none-eabi-nm}
FLASH_LIMIT=${2:-32768}; RAM_LIMIT=8192; FLASH_GOAL=${2:-16384}; RAM_GOAL=4096

sizes=$($SIZE -A "$elf")
section() { echo "$sizes" | awk -v s="$1" '$1 == s { print $2; f=1 } END { if (!f) print 0 }'; }
flash=$(( $(section .isr_vector) + $(section .text) + $(section .ARM.exidx) + $(section .data) ))
ram=$(( $(section .data) + $(section .bss) + $(section .stack) ))
echo "image: flash $flash B of $FLASH_LIMIT (goal $FLASH_GOAL), RAM $ram B of $RAM_LIMIT (goal $RAM_GOAL; .data $(section .data) + .bss $(section .bss) + stack $(section .stack))"

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
