/* memcpy, memmove, memset and memcmp for the size-first images (the
 * bootloaders, the Cortex-M0 application), and memcpy alone for the
 * Cortex-M0+ application (SMALL_MEM_MEMCPY_ONLY): byte loops, a fraction of
 * newlib-nano's size, which their budgets need (they copy a few dozen
 * bytes at a time). Built with -fno-tree-loop-distribute-patterns, so the
 * loops do not become calls to themselves. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#ifndef STARTUP_BOOTLOADER
/* A word that may alias any object (memcpy copies any type). */
typedef uint32_t __attribute__((may_alias)) any_word;
#endif

void *memcpy(void *restrict dst, const void *restrict src, size_t n)
{
    uint8_t *d = dst;
    const uint8_t *s = src;
    const uint8_t *end = s + n;
#ifndef STARTUP_BOOTLOADER
    /* The application's longest copies (ReadBatchData's 32 bytes, on the
     * way to an answer) come from word-aligned registers: read a word at a
     * time, stored a byte at a time, since the destination may be at any
     * byte and the Cortex-M0 faults on an unaligned word. */
#ifdef SMALL_MEM_MEMCPY_ONLY
    /* The Cortex-M0+ image's (hal/runtime/CMakeLists.txt): where both ends
     * are aligned (a stored record), a word a store too, four a pass, as
     * the C library's it replaces. */
    if ((((uintptr_t)s | (uintptr_t)d) & 3u) == 0u) {
        for (; end - s >= 16; s += 16, d += 16) {
            const any_word *from = (const any_word *)(const void *)s;
            any_word *to = (any_word *)(void *)d;
            to[0] = from[0];
            to[1] = from[1];
            to[2] = from[2];
            to[3] = from[3];
        }
        for (; end - s >= 4; s += 4, d += 4) {
            *(any_word *)(void *)d = *(const any_word *)(const void *)s;
        }
    } else
#endif
    if (((uintptr_t)s & 3u) == 0u) {
        for (; end - s >= 4; s += 4, d += 4) {
            uint32_t w = *(const any_word *)(const void *)s;
            d[0] = (uint8_t)w;
            d[1] = (uint8_t)(w >> 8);
            d[2] = (uint8_t)(w >> 16);
            d[3] = (uint8_t)(w >> 24);
        }
    }
#endif
    while (s != end) {
        *d++ = *s++;
    }
    return dst;
}

#ifndef SMALL_MEM_MEMCPY_ONLY
void *memmove(void *dst, const void *src, size_t n)
{
    uint8_t *d = dst;
    const uint8_t *s = src;
    if (d <= s) {
        while (n--) {
            *d++ = *s++;
        }
    } else {
        while (n--) {
            d[n] = s[n];
        }
    }
    return dst;
}

void *memset(void *dst, int c, size_t n)
{
    uint8_t *d = dst;
    while (n--) {
        *d++ = (uint8_t)c;
    }
    return dst;
}

int memcmp(const void *a, const void *b, size_t n)
{
    const uint8_t *x = a;
    const uint8_t *y = b;
    for (; n--; x++, y++) {
        if (*x != *y) {
            return *x - *y;
        }
    }
    return 0;
}
#endif
