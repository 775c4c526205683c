/* Fake servos behind an sb_transport, for the unit tests: they answer
 * Ping, ReadAngle, Monitor and Sync Monitor, and keep the setpoints they
 * were sent, on a clock that moves only as bytes cross the wire. */
#ifndef SERVOBUS_FAKE_SERVO_H
#define SERVOBUS_FAKE_SERVO_H

#include "servobus/servobus.h"

typedef struct fake_bus {
    uint64_t now_us;
    uint32_t baud;
    bool present[256];
    uint8_t out[2048]; /* answers waiting for the host */
    size_t out_len, out_at;
    int32_t setpoint[256]; /* the last StreamSetpoint angle each servo got */
    int16_t velocity[256];
    uint16_t stamp[256];
    uint32_t frames;       /* request frames taken */
    uint32_t setpoint_frames;
    bool garble_next;      /* the next answer's checksum is wrong */
} fake_bus;

void fake_init(fake_bus *f, uint32_t baud);
sb_transport fake_transport(fake_bus *f);

#endif
