/* The size-first images' mem* (hal/runtime/small_mem.c), built here
 * under other names: every alignment of source and destination and every
 * length up to 40 against the C library's; and the Cortex-M0+ image's
 * memcpy (SMALL_MEM_MEMCPY_ONLY: a word a store where both ends are
 * aligned) the same way. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

void *small_memcpy(void *restrict dst, const void *restrict src, size_t n);
void *m0p_memcpy(void *restrict dst, const void *restrict src, size_t n);
void *small_memmove(void *dst, const void *src, size_t n);
void *small_memset(void *dst, int c, size_t n);
int small_memcmp(const void *a, const void *b, size_t n);

enum { SPAN = 48, LONGEST = 40 };

static _Alignas(4) uint8_t source[SPAN];

typedef void *copy_fn(void *restrict dst, const void *restrict src, size_t n);

static void copy_every_alignment(copy_fn *copy)
{
    for (size_t i = 0; i < SPAN; i++) {
        source[i] = (uint8_t)(i * 37u + 11u);
    }
    for (size_t from = 0; from < 4u; from++) {
        for (size_t to = 0; to < 4u; to++) {
            for (size_t n = 0; n <= LONGEST; n++) {
                _Alignas(4) uint8_t got[SPAN];
                _Alignas(4) uint8_t want[SPAN];
                memset(got, 0xA5, sizeof got);
                memset(want, 0xA5, sizeof want);
                memcpy(&want[to], &source[from], n);
                assert_ptr_equal(copy(&got[to], &source[from], n), &got[to]);
                assert_memory_equal(got, want, sizeof got); /* nothing past n */
            }
        }
    }
}

static void test_copy_every_alignment(void **unused)
{
    (void)unused;
    copy_every_alignment(small_memcpy);
}

static void test_the_m0p_copy_every_alignment(void **unused)
{
    (void)unused;
    copy_every_alignment(m0p_memcpy);
}

static void test_move_overlapping(void **unused)
{
    (void)unused;
    for (size_t shift = 0; shift < 8u; shift++) {
        uint8_t got[SPAN];
        uint8_t want[SPAN];
        for (size_t i = 0; i < SPAN; i++) {
            got[i] = want[i] = (uint8_t)i;
        }
        memmove(&want[shift], want, 32);
        small_memmove(&got[shift], got, 32);
        assert_memory_equal(got, want, SPAN);
        memmove(want, &want[shift], 32);
        small_memmove(got, &got[shift], 32);
        assert_memory_equal(got, want, SPAN);
    }
}

static void test_set_and_compare(void **unused)
{
    (void)unused;
    uint8_t a[SPAN] = {0};
    small_memset(&a[3], 0x5A, 20);
    for (size_t i = 0; i < SPAN; i++) {
        assert_int_equal(a[i], i >= 3u && i < 23u ? 0x5A : 0);
    }
    uint8_t b[SPAN];
    memcpy(b, a, SPAN);
    assert_int_equal(small_memcmp(a, b, SPAN), 0);
    b[10] = 0x5B;
    assert_true(small_memcmp(a, b, SPAN) < 0);
    assert_true(small_memcmp(b, a, SPAN) > 0);
    assert_int_equal(small_memcmp(a, b, 10), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_copy_every_alignment),
        cmocka_unit_test(test_the_m0p_copy_every_alignment),
        cmocka_unit_test(test_move_overlapping),
        cmocka_unit_test(test_set_and_compare),
    };
    return cmocka_run_group_tests_name("small_mem", tests, NULL, NULL);
}
