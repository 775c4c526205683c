/* The simulator's servo is the reference board (its flash map and front
 * end), with a board ID of its own, so an image built for silicon is never
 * written into a simulated servo. servoctl reads the two numbers below. */
#ifndef SIM_BOARD_H
#define SIM_BOARD_H

#include "boards/stm32f103/board.h"

#undef BOARD_ID
#define BOARD_ID 0x5100 /* the update image header's board field */
#define BOARD_SIMULATED 1 /* its images are never executed: the slot's bytes stand for code */

#endif
