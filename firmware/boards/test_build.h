/* What a test build of a board's application does differently, and nothing
 * in a shipped one. SERVO_TEST_STUCK_AFTER_MS (servo_<board>_stuck, for
 * tools/tests/vboard): past that time since reset the main loop is stuck in
 * a loop that no longer reloads the watchdog, which must then reset the
 * chip. */
#ifndef BOARDS_TEST_BUILD_H
#define BOARDS_TEST_BUILD_H

#include "ports/stm32_common/systick_clock.h"

static inline void test_build_main_loop(void)
{
#ifdef SERVO_TEST_STUCK_AFTER_MS
    while (systick_now_us() >= (uint32_t)SERVO_TEST_STUCK_AFTER_MS * 1000u) {
    }
#endif
}

#endif
