#!/bin/sh
# Prints the image's name, its flash and RAM use against its own limits,
# and fails when it exceeds them or links any soft-float helper: firmware
# code is fixed point.
#   check-image.sh ELF [FLASH_LIMIT [RAM_LIMIT]]
# An application's limits are its board's (cmake/arm-image.cmake,
# servo_board_limits: its slot less the update image's header, and its
# part's RAM); a bootloader's, its 4 KB and its part's RAM. No image is
# judged against another part's budget: the Cortex-M0 board's own limits
# are the small part's (docs/footprint.md).
set -eu
elf=$1
SIZE=${SIZE:-arm-none-eabi-size}
NM=${NM:-arm-none-eabi-nm}
FLASH_LIMIT=${2:-32768}; RAM_LIMIT=${3:-8192}  # run by hand without limits: 32 KB, 8 KB

sizes=$($SIZE -A "$elf")
section() { echo "$sizes" | awk -v s="$1" '$1 == s { print $2; f=1 } END { if (!f) print 0 }'; }
flash=$(( $(section .isr_vector) + $(section .text) + $(section .ARM.exidx) + $(section .data) ))
# .ram_vectors: a Cortex-M0 image's vector table, copied to RAM.
ram=$(( $(section .ram_vectors) + $(section .data) + $(section .bss) + $(section .stack) ))
echo "image $(basename "$elf"): flash $flash B of $FLASH_LIMIT, RAM $ram B of $RAM_LIMIT (vectors $(section .ram_vectors) + .data $(section .data) + .bss $(section .bss) + stack $(section .stack))"

status=0
if [ "$flash" -gt "$FLASH_LIMIT" ]; then echo "error: $(basename "$elf"): flash $flash B exceeds $FLASH_LIMIT B" >&2; status=1; fi
if [ "$ram" -gt "$RAM_LIMIT" ]; then echo "error: $(basename "$elf"): RAM $ram B exceeds $RAM_LIMIT B" >&2; status=1; fi
soft=$($NM "$elf" | awk '{ print $NF }' |
       grep -E '^__aeabi_(f|d|[ui]2[fd]|[fd]2)|^__(add|sub|mul|div|neg|cmp|eq|ne|lt|le|gt|ge|unord)[sdt]f[23]$|^__(fix|float|extend|trunc)[a-z]*[sdt]f' || true)
if [ -n "$soft" ]; then
  echo "error: soft-float helpers linked (firmware code must be fixed point):" >&2
  echo "$soft" >&2
  status=1
fi
exit $status
