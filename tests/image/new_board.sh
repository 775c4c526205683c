#!/bin/sh
# A new board is one folder and its name in the board list: a copy of the
# reference board's folder under another name, with a board ID of its own,
# builds (bootloader, application and update image, every check after the
# link) with nothing else changed, and servoctl's image command knows it.
set -u
root=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The working tree as it is (new files included), without builds or caches.
(cd "$root" && tar --exclude=./build --exclude=./.git --exclude=./.venv --exclude='__pycache__' \
  -cf - .) | (cd "$tmp" && tar -xf -) || exit 1
cp -r "$tmp/firmware/boards/stm32f103" "$tmp/firmware/boards/my_servo"
sed -i 's/^#define BOARD_ID 0x0103\b/#define BOARD_ID 0x0777/' "$tmp/firmware/boards/my_servo/board.h"
grep -q '^#define BOARD_ID 0x0777' "$tmp/firmware/boards/my_servo/board.h" || { echo "board ID not set"; exit 1; }
cmake -S "$tmp" -B "$tmp/build" -G Ninja -DCMAKE_TOOLCHAIN_FILE="$tmp/cmake/arm-none-eabi.cmake" \
  -DCMAKE_BUILD_TYPE=MinSizeRel -DSERVO_BOARDS=my_servo >"$tmp/configure.log" 2>&1 ||
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
echo "new board: a copied folder builds as my_servo (board 0x0777)"
