/* Fake servos behind an sb_transport, for the unit tests: they answer
 * Ping, ReadAngle, Monitor and Sync Monitor, and keep the setpoints they
 * were sent, on a clock that moves only as bytes cross the wire and as the
 * host waits. An answer starts FAKE_FIRST_US after the request (FAKE_NEXT_US
 * after the answer before it); a listed servo that is silent holds the next
 * one's turn for SB_SYNC_SILENCE_US, as the firmware does. */
#ifndef SERVOBUS_FAKE_SERVO_H
#define SERVOBUS_FAKE_SERVO_H

#include "servobus/servobus.h"

typedef struct fake_bus {
    uint64_t now_us;
    uint32_t baud;
    bool present[256];
    uint8_t out[2048]; /* answers waiting for the host */
    size_t out_len, out_at;
    size_t ends[64];       /* where each answer in out ends */
    uint64_t ready_us[64]; /* and when its last byte is off the wire */
    size_t answers;
    uint64_t line_us;      /* the line's last activity */
    bool first;            /* the next answer is the request's first */
    uint8_t late[64];      /* bytes that come at the start of the next request: */
    size_t late_len;       /* a late answer to the one before */
    int32_t setpoint[256]; /* the last StreamSetpoint angle each servo got */
    int16_t velocity[256];
    uint16_t stamp[256];
    uint32_t frames;       /* request frames taken */
    uint32_t setpoint_frames;
    bool garble_next;      /* the next answer's checksum is wrong */
    uint8_t cut[256];      /* a servo's answers stop after this many bytes (0: whole) */
    bool one_short[256];   /* a servo's answers a byte short, their checksum good */
    uint32_t fail_writes;  /* writes to fail (-EIO), nothing sent */
    int64_t power[3];      /* the Monitor answers' mV, mA and mW (mV 0: 7400) */
} fake_bus;

void fake_init(fake_bus *f, uint32_t baud);
sb_transport fake_transport(fake_bus *f);

#define FAKE_FIRST_US 47u
#define FAKE_NEXT_US 6u

#endif
