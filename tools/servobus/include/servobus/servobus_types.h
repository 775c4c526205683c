/* servobus: the servo protocol for hosts in C99 (docs/c-library.md).
 * The types every part shares: errors as values, the schema's tables, a
 * field's value, the transport. C and C++ alike: no allocation, no OS. */
#ifndef SERVOBUS_TYPES_H
#define SERVOBUS_TYPES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What went wrong; SB_OK is 0. */
typedef enum sb_status {
    SB_OK = 0,
    SB_E_RANGE,          /* a field's value beyond the schema's range: nothing sent */
    SB_E_USAGE,          /* a call the protocol does not allow (field: what; value, least, most: how) */
    SB_E_UNKNOWN_PACKET, /* a code the schema does not have */
    SB_E_UNKNOWN_ITEM,   /* a data item the schema does not have (ReadData, WriteData), or not writable (value: it) */
    SB_E_SPACE,          /* the caller's buffer is too small (value: bytes needed, most: given) */
    SB_E_NO_ANSWER,      /* the servo did not answer in time */
    SB_E_BAD_CHECKSUM,   /* an answer came with a bad checksum */
    SB_E_BAD_ANSWER,     /* an answer of the wrong length, or a field beyond its range */
    SB_E_LINK,           /* the transport failed (os_error says why) */
    SB_E_DUPLICATE_ID,   /* a servo listed twice (each answers once a round): nothing sent */
    SB_E_BROADCAST       /* the broadcast ID where no servo would carry it out or answer: nothing sent */
} sb_status;

/* An error as a value: which servo (-1: none or unknown), which packet
 * (0: none), which field, the value and the range it broke. */
typedef struct sb_error {
    sb_status status;
    int16_t servo;
    uint8_t packet;
    const char *field;
    int64_t value;
    int64_t least;
    int64_t most;
    int os_error; /* errno of a link error, else 0 */
} sb_error;

/* A field's type in the schema. */
typedef enum sb_field_type { SB_U8, SB_U16, SB_U32, SB_I16, SB_I32, SB_ITEM, SB_USER_AREA, SB_BYTES } sb_field_type;
/* What the servo does with a request's value beyond the field's range. */
typedef enum sb_out { SB_OUT_NONE, SB_OUT_CLAMP, SB_OUT_REFUSE } sb_out;
typedef enum sb_access { SB_ACCESS_READ, SB_ACCESS_READ_WRITE, SB_ACCESS_RESERVED } sb_access;

typedef struct sb_field_desc {
    const char *name;
    uint8_t type;   /* sb_field_type */
    uint8_t ranged; /* the schema gives a range narrower than the type's */
    uint8_t out;    /* sb_out */
    int64_t min;    /* the field's range: the schema's, else the type's */
    int64_t max;
} sb_field_desc;

typedef struct sb_packet_desc {
    uint8_t code;
    const char *name;
    uint16_t flags;        /* SB_PF_* */
    uint16_t length_min;   /* the request content's bytes; 65535: no bound */
    uint16_t length_max;
    uint8_t request_count; /* fields */
    uint8_t answer_count;
    const sb_field_desc *request;
    const sb_field_desc *answer;
} sb_packet_desc;

typedef struct sb_item_desc {
    uint8_t id;
    uint8_t size;
    uint8_t is_signed;
    uint8_t access; /* sb_access */
    int64_t min;    /* a writable item's range; else its type's */
    int64_t max;
    const char *name;
} sb_item_desc;

/* One field's value: a number (n), or bytes (a user area, a block); an
 * item's value is n with len its size. */
typedef struct sb_value {
    int64_t n;
    const uint8_t *bytes;
    size_t len;
} sb_value;

/* The link. write: every byte, 0 or -errno. read: up to cap bytes, at
 * least one unless wait_us passes first (then 0), -errno on failure;
 * want is how many bytes would complete what the bus waits for (a hint: a
 * transport may wake only once they are there). now_us: the bus's clock. */
typedef struct sb_transport {
    void *ctx;
    int (*write)(void *ctx, const uint8_t *data, size_t len);
    int (*read)(void *ctx, uint8_t *buf, size_t cap, size_t want, uint32_t wait_us);
    uint64_t (*now_us)(void *ctx);
} sb_transport;

typedef struct sb_bus sb_bus;

#ifdef __cplusplus
}
#endif

#endif
