#!/bin/sh
# A new board is one folder and its name in the board list: a copy of the
# reference board's folder (its data: board.h, board.cmake, CMakeLists.txt;
# its code is the F1 boards' shared one) under another name, with a board
# ID of its own, builds (bootloader, application and update image, every
# check after the link) with nothing else changed, and servoctl's image
# command knows it; one whose bus is another USART is its board.h alone,
# and one whose bus names DMA channels or a TX pin its USART does not have
# is refused, naming RM0008.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The working tree as it is (new files included), without builds or caches.
(cd "$root" && tar --exclude=./build --exclude=./.git --exclude=./.venv --exclude='__pycache__' \
  -cf - .) | (cd "$tmp" && tar -xf -) || exit 1
# copy NAME ID [USART TX RX [PIN]]: the reference board's folder as NAME, its
# ID and, given them, its bus's USART, DMA channels and TX pin changed
# (board.h only; with the pin, the NTC moves off PA2 to ADC input 4).
copy() {
  cp -r "$tmp/firmware/boards/stm32f103" "$tmp/firmware/boards/$1"
  h=$tmp/firmware/boards/$1/board.h
  sed -i "s/^#define BOARD_ID 0x0103\\b/#define BOARD_ID $2/" "$h"
  grep -q "^#define BOARD_ID $2" "$h" || { echo "board ID not set"; exit 1; }
  [ $# -ge 5 ] || return 0
  sed -i -e "s/^#define BOARD_BUS_USART 1$/#define BOARD_BUS_USART $3/" \
    -e "s/^#define BOARD_BUS_DMA_TX 4$/#define BOARD_BUS_DMA_TX $4/" \
    -e "s/^#define BOARD_BUS_DMA_RX 5$/#define BOARD_BUS_DMA_RX $5/" "$h"
  grep -q "^#define BOARD_BUS_DMA_RX $5" "$h" || { echo "bus not set"; exit 1; }
  [ $# -eq 6 ] || return 0
  sed -i -e "s/^#define BOARD_BUS_TX_PIN 0x09$/#define BOARD_BUS_TX_PIN $6/" \
    -e "s/^#define BOARD_ADC_NTC 2$/#define BOARD_ADC_NTC 4/" "$h"
  grep -q "^#define BOARD_BUS_TX_PIN $6" "$h" || { echo "TX pin not set"; exit 1; }
}
copy my_servo 0x0777
copy my_servo_usart2 0x0778 0x2 7 6 0x02  # a variant from data alone: its bus on USART2, PA2
cmake -S "$tmp" -B "$tmp/build" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$tmp/cmake/arm-none-eabi.cmake" \
  -DCMAKE_BUILD_TYPE=MinSizeRel "-DSERVO_BOARDS=my_servo;my_servo_usart2" >"$tmp/configure.log" 2>&1 ||
  { tail -20 "$tmp/configure.log"; echo "the new board did not configure"; exit 1; }
cmake --build "$tmp/build" >"$tmp/build.log" 2>&1 ||
  { tail -30 "$tmp/build.log"; echo "the new board did not build"; exit 1; }
out=$tmp/build/firmware/boards/my_servo
for f in servo_my_servo.bin servo_my_servo_boot.bin servo_my_servo.img; do
  [ -s "$out/$f" ] || { echo "no $f"; exit 1; }
done
# The update image's header carries the new board's ID (bytes 6-7, little-endian).
id=$(od -An -tx1 -j6 -N2 "$out/servo_my_servo.img" | tr -d ' \n')
[ "$id" = "7707" ] || { echo "the image's board field is $id, not 0x0777"; exit 1; }
# Its folder is its data: the code is the F1 boards' shared one.
[ -z "$(find "$tmp/firmware/boards/my_servo" -name '*.c')" ] || { echo "the reference board's folder has code"; exit 1; }
# The USART2 variant's vector table calls its handlers at USART2's and DMA1
# channel 6's slots (RM0008: interrupts 38 and 16, after the 16 core ones).
elf=$tmp/build/firmware/boards/my_servo_usart2/servo_my_servo_usart2.elf
arm-none-eabi-objcopy -O binary --only-section=.isr_vector "$elf" "$tmp/vectors.bin"
for pair in USART2_IRQHandler:54 DMA1_Channel6_IRQHandler:32; do
  name=${pair%%:*}; slot=${pair##*:}
  want=$(arm-none-eabi-nm "$elf" | awk -v n="$name" '$3 == n && $2 == "T" {print $1}')
  [ -n "$want" ] || { echo "$name is not the board's own (still the weak default)"; exit 1; }
  got=$(od -An -tx4 -j $((slot * 4)) -N4 "$tmp/vectors.bin" | tr -d ' ')
  [ $((0x$got & ~1)) -eq $((0x$want)) ] || { echo "vector $slot is $got, not $name at $want"; exit 1; }
done
# A bus whose DMA channels, or whose TX pin, are not its USART's stops the
# build, naming the fact (every failing file tried: -k 0).
copy bad_bus 0x0779 2 4 5 0x02
copy bad_pin 0x077A 1 4 5 0x02
cmake -S "$tmp" -B "$tmp/bad" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$tmp/cmake/arm-none-eabi.cmake" \
  -DCMAKE_BUILD_TYPE=MinSizeRel "-DSERVO_BOARDS=bad_bus;bad_pin" >/dev/null 2>&1 || { echo "bad boards did not configure"; exit 1; }
if cmake --build "$tmp/bad" -- -k 0 >"$tmp/bad.log" 2>&1; then echo "a bus on the wrong DMA channels or pin built"; exit 1; fi
grep -q "are not its USART.*DMA1 channels (RM0008 Table 78" "$tmp/bad.log" || { tail -5 "$tmp/bad.log"; echo "no reason given"; exit 1; }
grep -q "BOARD_BUS_TX_PIN is not its USART's TX (RM0008 9.3.8" "$tmp/bad.log" || { tail -5 "$tmp/bad.log"; echo "no reason for the pin"; exit 1; }
# A fact written other than as a plain number (a C suffix) stops the
# configure, naming it: the linker script and the tools read them as numbers.
copy suffixed 0x077B 0x2 7 6u 0x02
if cmake -S "$tmp" -B "$tmp/suffixed" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$tmp/cmake/arm-none-eabi.cmake" \
  -DCMAKE_BUILD_TYPE=MinSizeRel "-DSERVO_BOARDS=suffixed" >"$tmp/suffixed.log" 2>&1; then
  echo "a board fact with a suffix configured"; exit 1
fi
grep -q "BOARD_BUS_DMA_RX is '6u': a board fact is a plain number" "$tmp/suffixed.log" ||
  { tail -5 "$tmp/suffixed.log"; echo "no reason for the suffix"; exit 1; }
echo "new board: a copied folder builds as my_servo (board 0x0777), one with its bus on USART2 as data"
