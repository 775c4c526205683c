/* What the status area says about this firmware (data IDs 6 and 7). */
#ifndef APP_IDENTITY_H
#define APP_IDENTITY_H

/* Model code reported in data ID 6: 0x0F00 marks this open firmware on its
 * reference board, distinct from the maker's model codes. */
#define SERVO_MODEL 0x0F00u

/* Data ID 7: major.minor.patch as 0xMMmp (one nibble each for minor and
 * patch), from the CMake project version. */
#ifndef FIRMWARE_VERSION
#define FIRMWARE_VERSION 0x0010u
#endif

#endif
