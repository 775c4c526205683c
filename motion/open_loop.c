/* Open loop (DriveDuty, 0x46): the bridge at a fixed duty for a time, then
 * released, so a host can identify the drive train from the response
 * (servoctl identify). It runs damping mode's tick with the duty in place
 * of the brake, but counts as driven (motion_is_released): the bus watchdog
 * covers it, and ReadMotion does not call it released. The output's
 * current limit (item 42's power, the current protection, a stall's cap)
 * and the protections hold it as they hold any move. The angle limits do
 * not: nothing here knows where the horn goes. */
#include "motion/motion_internal.h"

enum motion_submit_result motion_drive_duty(struct motion *m, int16_t duty_q15, uint16_t ms)
{
    if (m->inhibit || ms == 0u || ms > MOTION_OPEN_LOOP_MAX_MS || duty_q15 == 0) {
        return MOTION_REFUSED; /* not counted: it leaves the watchdog's act standing */
    }
    motion_take_over(m);
    m->running = 0;
    m->streaming = 0;
    m->endless = 0;
    m->mode = MODE_OPEN_LOOP;
    m->open_duty_q15 = duty_q15 < -32767 ? -32767 : duty_q15;
    m->open_ticks = (uint16_t)(ms * (MOTION_TICK_HZ / 1000u));
    return MOTION_ACCEPTED;
}
