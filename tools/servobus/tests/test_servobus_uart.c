/* servobus over a microcontroller's UART callbacks (sb_uart_transport):
 * the fake servos' bytes handed over one at a time, as a UART's receive
 * callback gives them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "tests/fake_servo.h"

static fake_bus fake;

static int set_up(void **state)
{
    fake_init(&fake, 1000000);
    return 0;
}

/* The UART callbacks: the fake's bytes handed over one at a time. */
static uint8_t uart_in[256];
static size_t uart_in_len, uart_in_at;

static void uart_send(void *ctx, const uint8_t *data, size_t len)
{
    fake_bus *f = (fake_bus *)ctx;
    sb_transport t = fake_transport(f);
    t.write(f, data, len);
    /* What the caller has not read stays queued before the answer, as in a UART's ring. */
    memmove(uart_in, uart_in + uart_in_at, uart_in_len - uart_in_at);
    uart_in_len -= uart_in_at;
    uart_in_at = 0;
    int n;
    while ((n = t.read(f, uart_in + uart_in_len, sizeof uart_in - uart_in_len, 1, 100000)) > 0)
        uart_in_len += (size_t)n;
}

static int uart_recv(void *ctx)
{
    (void)ctx;
    return uart_in_at < uart_in_len ? uart_in[uart_in_at++] : -1;
}

static uint64_t uart_now(void *ctx)
{
    return ++((fake_bus *)ctx)->now_us;
}

static void the_uart_callbacks_carry_a_request(void **state)
{
    sb_uart u = {uart_send, uart_recv, uart_now, &fake};
    sb_bus ubus;
    sb_bus_init(&ubus, sb_uart_transport(&u), 1000000);
    fake.present[9] = true;
    sb_ping_request p = {9};
    sb_ping_answer a;
    assert_int_equal(sb_call_ping(&ubus, &p, &a).status, SB_OK);
    assert_int_equal(a.id, 9);
    p.id = 8;
    assert_int_equal(sb_call_ping(&ubus, &p, &a).status, SB_E_NO_ANSWER);
}

/* Answers that came after their call gave up wait in the UART's queue: the
 * next call drops them all before it sends, however many (here 12 late
 * ReadAngle answers, 96 bytes; it dropped 64 and took the rest's first as
 * its own answer, angle 100 for -123). */
static void late_bytes_in_the_uarts_queue_are_dropped_before_a_request(void **state)
{
    sb_uart u = {uart_send, uart_recv, uart_now, &fake};
    sb_bus ubus;
    sb_bus_init(&ubus, sb_uart_transport(&u), 1000000);
    fake.present[3] = true;
    uart_in_len = uart_in_at = 0;
    for (int k = 0; k < 12; k++) {
        sb_value v[2] = {{3, NULL, 0}, {100, NULL, 0}};
        size_t len = 0;
        assert_int_equal(sb_encode_answer(SB_PKT_READ_ANGLE, v, 2, uart_in + uart_in_len,
                                          sizeof uart_in - uart_in_len, &len).status, SB_OK);
        uart_in_len += len;
    }
    assert_true(uart_in_len > 64);
    sb_read_angle_request r = {3};
    sb_read_angle_answer a;
    assert_int_equal(sb_call_read_angle(&ubus, &r, &a).status, SB_OK);
    assert_int_equal(a.angle, -123);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(the_uart_callbacks_carry_a_request, set_up),
        cmocka_unit_test_setup(late_bytes_in_the_uarts_queue_are_dropped_before_a_request, set_up),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
