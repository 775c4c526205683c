#include "support/frames.h"

static size_t finish(uint8_t *out, size_t n)
{
    unsigned sum = 0;
    for (size_t i = 0; i < n; i++) {
        sum += out[i];
    }
    out[n] = (uint8_t)(sum % 256u);
    return n + 1;
}

size_t make_request(uint8_t *out, uint8_t code, const uint8_t *content, size_t length)
{
    size_t n = 0;
    out[n++] = 0x12;
    out[n++] = 0x4C;
    out[n++] = code;
    if (length >= 255) {
        out[n++] = 0xFF;
        out[n++] = (uint8_t)(length & 0xFF);
        out[n++] = (uint8_t)(length >> 8);
    } else {
        out[n++] = (uint8_t)length;
    }
    for (size_t i = 0; i < length; i++) {
        out[n++] = content[i];
    }
    return finish(out, n);
}

size_t make_response(uint8_t *out, uint8_t code, const uint8_t *content, size_t length)
{
    size_t n = 0;
    out[n++] = 0x05;
    out[n++] = 0x1C;
    out[n++] = code;
    out[n++] = (uint8_t)length;
    for (size_t i = 0; i < length; i++) {
        out[n++] = content[i];
    }
    return finish(out, n);
}
