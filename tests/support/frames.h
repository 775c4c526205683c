/* Builds request and response frames for tests: an implementation of the
 * framing rules separate from the firmware's own. */
#ifndef TEST_FRAMES_H
#define TEST_FRAMES_H

#include <stddef.h>
#include <stdint.h>

/* A request frame; lengths of 255 and more use the extended length. */
size_t make_request(uint8_t *out, uint8_t code, const uint8_t *content, size_t length);
/* A response frame, as another servo (or this one) sends it. */
size_t make_response(uint8_t *out, uint8_t code, const uint8_t *content, size_t length);

#endif
