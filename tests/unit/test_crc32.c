/* The application's table CRC-32 and the bootloader's bitwise one
 * (CRC32_BITWISE) give the zlib CRC, the same for any bytes: the
 * bootloader checks what the application's store and images wrote. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "runtime/crc32.h"

/* The bootloader's build of the same source, under other names. */
#define CRC32_BITWISE
#define crc32 crc32_bitwise
#define crc32_update crc32_update_bitwise
#include "runtime/crc32.c"
#undef crc32
#undef crc32_update

static void test_the_check_value(void **state)
{
    (void)state;
    const uint8_t check[] = "123456789";
    assert_int_equal(crc32(check, 9), 0xCBF43926u); /* CRC-32/ISO-HDLC's check */
    assert_int_equal(crc32_bitwise(check, 9), 0xCBF43926u);
    assert_int_equal(crc32(check, 0), 0u);
}

static void test_both_agree_on_every_byte_and_in_pieces(void **state)
{
    (void)state;
    uint8_t data[300];
    uint32_t x = 12345u;
    for (size_t i = 0; i < sizeof data; i++) {
        x = x * 1103515245u + 12345u; /* any bytes will do; these repeat */
        data[i] = (uint8_t)(x >> 16);
    }
    for (size_t n = 0; n <= sizeof data; n++) {
        assert_int_equal(crc32(data, n), crc32_bitwise(data, n));
    }
    uint32_t state_pieces = crc32_update(CRC32_START, data, 100);
    state_pieces = crc32_update(state_pieces, &data[100], 200);
    assert_int_equal(~state_pieces, crc32(data, 300));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_the_check_value),
        cmocka_unit_test(test_both_agree_on_every_byte_and_in_pieces),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
