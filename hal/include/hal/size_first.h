#ifndef HAL_SIZE_FIRST_H
#define HAL_SIZE_FIRST_H

/* A helper that the size-first image (SERVO_SIZE_FIRST: the Cortex-M0)
 * calls where the others inline it at each caller: for one inlined at
 * several callers, off every timed path. Here, in the lowest layer, so
 * every layer above can mark its own. */
#ifdef SERVO_SIZE_FIRST
#define SIZE_FIRST_CALLED __attribute__((noinline))
#else
#define SIZE_FIRST_CALLED
#endif

#endif
