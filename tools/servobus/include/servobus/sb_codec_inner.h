/* What the codec gives the encoder above it (sb_encode.c) and nothing
 * else: a request's or an answer's fields and frame, each field against its
 * range, without the rules a request's fields keep together. */
#ifndef SERVOBUS_SB_CODEC_INNER_H
#define SERVOBUS_SB_CODEC_INNER_H

#include "servobus/servobus.h"

sb_error sb_encode_fields(uint8_t code, bool request, const sb_value *v, size_t count, uint8_t *out, size_t cap,
                          size_t *len);
sb_error sb_encode_frame(uint8_t code, bool request, const sb_value *v, size_t count, uint8_t *frame, size_t cap,
                         size_t *len);

#endif
