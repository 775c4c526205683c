/* cmocka mock of motion/motion.h for dispatcher tests. motion_submit keeps
 * the last command it was given in motion_mock_last. */
#ifndef TEST_MOTION_MOCK_H
#define TEST_MOTION_MOCK_H

#include "motion/motion.h"

extern struct motion_command motion_mock_last;
/* The last setpoint motion_stream was given. */
extern struct motion_setpoint motion_mock_last_setpoint;

/* Calls of motion_drive_train_changed (a stored item changed) so far. */
extern unsigned motion_mock_drive_changes;
/* drive_items_stable says false for this torque constant (item 81); 0 none. */
extern uint16_t motion_mock_unstable_kt;

#endif
