#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "doubles/motion_mock.h"

struct motion_command motion_mock_last;

enum motion_submit_result motion_submit(struct motion *m, const struct motion_command *cmd)
{
    (void)m;
    function_called();
    motion_mock_last = *cmd;
    return (enum motion_submit_result)mock();
}

struct motion_setpoint motion_mock_last_setpoint;

enum motion_submit_result motion_stream(struct motion *m, const struct motion_setpoint *sp)
{
    (void)m;
    function_called();
    motion_mock_last_setpoint = *sp;
    return (enum motion_submit_result)mock();
}

enum motion_submit_result motion_drive_duty(struct motion *m, int16_t duty_q15, uint16_t ms)
{
    (void)m;
    check_expected(duty_q15);
    check_expected(ms);
    return (enum motion_submit_result)mock();
}

void motion_read_angle(const struct motion *m, struct motion_angle *out)
{
    (void)m;
    *out = *mock_ptr_type(const struct motion_angle *);
}

void motion_read_diagnostics(const struct motion *m, struct motion_diagnostics *out)
{
    (void)m;
    *out = *mock_ptr_type(const struct motion_diagnostics *);
}

bool motion_reset_multi_turn(struct motion *m)
{
    (void)m;
    function_called();
    return (bool)mock();
}

bool motion_set_origin(struct motion *m)
{
    (void)m;
    function_called();
    return (bool)mock();
}

void motion_begin_async(struct motion *m)
{
    (void)m;
    function_called();
}

void motion_end_async(struct motion *m, bool cancel)
{
    (void)m;
    check_expected(cancel);
}

bool motion_is_idle(const struct motion *m)
{
    (void)m;
    function_called();
    return (bool)mock();
}

unsigned motion_mock_drive_changes;

void motion_drive_train_changed(struct motion *m)
{
    (void)m;
    motion_mock_drive_changes++;
}

uint16_t motion_mock_unstable_kt;

bool drive_items_stable(const struct user_config *dt)
{
    return dt->kt_un_m_per_a != motion_mock_unstable_kt;
}
