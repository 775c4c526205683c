/* The board an image is built for, in vector 7 of its table: a slot that
 * ARMv6-M and ARMv7-M reserve and no core reads. Two boards' applications
 * can share a link address and a RAM size; this word tells them apart, so
 * `servoctl image` refuses to pack one board's binary for another
 * (bootloader/servo_image reads it). Its value is the linker's symbol
 * _board_mark (the linker scripts app.ld.in and boot.ld.in, from the
 * board's board.h): "SB" in the high half, BOARD_ID in the low half. */
#ifndef STARTUP_BOARD_MARK_H
#define STARTUP_BOARD_MARK_H

#include <stdint.h>

#define BOARD_MARK_VECTOR 7

extern uint32_t _board_mark; /* its address is the mark, as _estack's is the stack's top */

#define BOARD_MARK ((void (*)(void))(uintptr_t)&_board_mark)

#endif
