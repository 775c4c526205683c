/* servobus: the servo protocol for hosts, in C99 (docs/c-library.md).
 *
 * Every packet of protocol/servo_schema (the maker's and this firmware's)
 * is encoded and decoded from the schema's own tables (sb_schema.h, made
 * by scripts/gen_protocol.py), every field checked against its range before
 * anything is sent. The bus, the Sync Monitor, SyncCommand, the stream of
 * setpoints and the robot loop run over any sb_transport: a serial port or
 * a TCP socket (servobus_posix.h), or a microcontroller's UART
 * (sb_uart_transport). No allocation, no OS: every buffer is the caller's
 * or in these structs. Errors are values (sb_error) naming the servo, the
 * packet and the field; sb_error_text says them in words. */
#ifndef SERVOBUS_H
#define SERVOBUS_H

#include "servobus/servobus_types.h"
#include "servobus/sb_schema.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most servos a stream or a robot loop takes (a plain number). */
#ifndef SB_MAX_SERVOS
#define SB_MAX_SERVOS 32
#endif
/* A program built with another SB_MAX_SERVOS than the library's would
 * disagree with it on the structs' sizes (sb_bus_init wrote past a smaller
 * sb_bus): the functions that set them up carry the number in their link
 * names, so such a program does not link (sb_bus_init_max_16 undefined). */
#define SB_ABI_PASTE(a, b) a##b
#define SB_ABI_NAME(a, b) SB_ABI_PASTE(a, b)
#define sb_bus_init SB_ABI_NAME(sb_bus_init_max_, SB_MAX_SERVOS)
#define sb_stream_init SB_ABI_NAME(sb_stream_init_max_, SB_MAX_SERVOS)
#define sb_loop_init SB_ABI_NAME(sb_loop_init_max_, SB_MAX_SERVOS)
#define SB_BITS_PER_BYTE 10u /* 8N1 */
#define SB_TX_MAX (16u + 10u * SB_MAX_SERVOS + 8u + SB_MAX_SERVOS)
#define SB_RX_MAX 256u
/* The servos' documented turnaround (docs/decisions.md, "Sync Monitor
 * turn-taking", docs/sleep.md "The first answer"): an answer starts
 * within SB_TURNAROUND_US plus 2 byte times of the line's last activity,
 * and a listed servo silent for SB_SYNC_SILENCE_US passes its turn (the
 * firmware's SYNC_SLOT_SILENCE_US). */
#define SB_TURNAROUND_US 50u
#define SB_SYNC_SILENCE_US 3000u
/* sb_bus.answer_margin_us's default: the host's link on top of the wire (a
 * USB-serial adapter hands bytes over each 1 ms frame). */
#define SB_ANSWER_MARGIN_US 2000u

sb_error sb_ok(void);
/* An error naming servo (-1: none), packet (0: none) and field (NULL: none). */
sb_error sb_error_of(sb_status status, int servo, uint8_t packet, const char *field);
/* A transport from its parts (sb_transport's fields). */
sb_transport sb_transport_make(void *ctx, int (*write)(void *, const uint8_t *, size_t),
                               int (*read)(void *, uint8_t *, size_t, size_t, uint32_t), uint64_t (*now_us)(void *));
/* The error in words, NUL-terminated in buf: the servo, the packet, the
 * field, what went wrong and the value and range it carries, e.g.
 * "servo 3: MoveOnAngleMode: angle out of range: 1801 is beyond
 * -1800..1800; nothing was sent", "StreamSetpoint: ids not allowed: 33
 * servos is beyond 1..32 (SB_MAX_SERVOS)", "servo 3: ReadAngle: no answer
 * in time (is it on the bus, ...)", "servo 3: Ping: the link failed (errno
 * 5: Input/output error)" (the errno's name on a POSIX host). Returns the
 * length written (cut to cap - 1). */
size_t sb_error_text(const sb_error *e, char *buf, size_t cap);
/* The IDs a round lists (code: its packet, for the error): each a servo's,
 * once (SB_E_BROADCAST, SB_E_DUPLICATE_ID naming it). */
sb_error sb_check_ids(const uint8_t *ids, size_t count, uint8_t code);
const sb_packet_desc *sb_packet(uint8_t code); /* NULL: not in the schema */
const sb_item_desc *sb_item(uint8_t id);       /* NULL: not in the schema */

/* ---- the codec: any packet from its fields' values (schema order) ----- */
/* A request's content / whole frame. Each number is checked against its
 * field's range (the schema's, else its type's): beyond it, SB_E_RANGE and
 * nothing written. An item's value (WriteData) takes the item's size and
 * range; a request's length against the packet's. */
sb_error sb_encode_content(uint8_t code, const sb_value *v, size_t count, uint8_t *out, size_t cap, size_t *len);
sb_error sb_encode_request(uint8_t code, const sb_value *v, size_t count, uint8_t *frame, size_t cap, size_t *len);
/* A request's fields' ranges (each number's: SB_E_RANGE; an item's value
 * is the encoders'), then the rules across them: a move's time shorter
 * than its ramps (the servo would stretch it: SB_E_RANGE); a SyncCommand's records
 * not of a syncable packet at its length, or not as many as it says
 * (SB_E_USAGE), and each record checked as its packet's request (its
 * fields' ranges: SB_E_RANGE; these rules; its servo's ID: SB_E_BROADCAST
 * for 255, SB_E_DUPLICATE_ID for one listed twice). The encoders above
 * apply it. */
sb_error sb_check_request(uint8_t code, const sb_value *v, size_t count);
/* An answer's frame (a servo's side: the tests' fake servos, cross-checks). */
sb_error sb_encode_answer(uint8_t code, const sb_value *v, size_t count, uint8_t *frame, size_t cap, size_t *len);
/* A frame around a content: header, code, length (extended from 255), checksum. */
sb_error sb_frame(bool request, uint8_t code, const uint8_t *content, size_t clen, uint8_t *frame, size_t cap,
                  size_t *len);
/* Content into values (bytes point into content). count: the packet's
 * fields exactly. Lengths and answer ranges checked: SB_E_BAD_ANSWER. */
sb_error sb_decode_answer(uint8_t code, const uint8_t *content, size_t len, sb_value *v, size_t count);
sb_error sb_decode_request(uint8_t code, const uint8_t *content, size_t len, sb_value *v, size_t count);
uint8_t sb_checksum(const uint8_t *data, size_t len);

/* A frame finder over a stream of bytes: sb_parse returns 1 when a frame
 * (header as given) ends in the bytes fed so far, with its code and
 * content; bytes outside frames and frames with a bad checksum are counted.
 * A false header (noise, an answer cut short) costs only its bytes: the
 * search goes on from the byte after it, through the bytes held. Every
 * frame is returned as its last byte comes, whatever frames it overlaps:
 * an answer whose content holds a whole frame, or whose first bytes made a
 * good checksum with noise before it, is not lost (the caller skips what
 * it did not ask for). */
typedef struct sb_parser {
    uint8_t header[2];
    uint8_t buf[2 * SB_RX_MAX]; /* byte x at x % SB_RX_MAX and again SB_RX_MAX on: a frame is in one piece */
    uint8_t sum[SB_RX_MAX];     /* at x % SB_RX_MAX: the sum of the bytes before byte x */
    uint16_t size[SB_RX_MAX];   /* at s % SB_RX_MAX: the frame begun at byte s, its size and state */
    uint16_t next[SB_RX_MAX];   /* the next frame (by start) that ends where the one at s does */
    uint16_t ends[SB_RX_MAX];   /* at e % SB_RX_MAX: the first frame (by start) ending at byte e */
    uint32_t now;               /* bytes taken */
    uint32_t lo;                /* the first byte of the earliest frame still open (now: none) */
    uint32_t reach;             /* the end of the frames returned */
    uint32_t start, end;        /* the frame returned last: its first byte, and the byte after its last */
    uint32_t cover;             /* the end of the frames begun at the bytes judged stray or not */
    uint16_t cursor;            /* the next frame to check that ends at byte now - 1 */
    bool open;                  /* the byte now - 1's frames not all checked */
    size_t len;                 /* bytes held: now - lo */
    uint32_t stray_bytes;
    uint32_t bad_frames;
} sb_parser;
void sb_parser_init(sb_parser *p, bool requests);
/* Takes what it can of data (*used: how much); 1: a frame (code, content
 * valid until the next call), 0: none yet and all of data taken. Call it
 * again after a 1, with no data if none is left: the bytes held may hold
 * another frame. */
int sb_parse(sb_parser *p, const uint8_t *data, size_t len, size_t *used, uint8_t *code, const uint8_t **content,
             size_t *clen);
/* Drops every byte held (the counts stay): a new request's answers. */
void sb_parser_clear(sb_parser *p);
/* The bytes that would complete the frame the parser is in (at least 1). */
size_t sb_parser_missing(const sb_parser *p);

/* ---- the bus ---------------------------------------------------------- */
struct sb_bus {
    sb_transport t;
    uint32_t baud;       /* for the wire's times */
    uint32_t timeout_us; /* an answer's, after the request (default 100 ms) */
    /* A Sync Monitor answer's wait beyond its bytes and the servos'
     * turnaround (default SB_ANSWER_MARGIN_US): the link's latency. */
    uint32_t answer_margin_us;
    uint64_t sent_end_us; /* the bus clock when the last request's bytes end on the wire */
    sb_parser rx;
    uint8_t pending[SB_RX_MAX]; /* read but not yet parsed */
    size_t pending_len;
    uint64_t arrived_us; /* the bus clock when the last answer was taken */
    uint8_t tx[SB_TX_MAX];
};
void sb_bus_init(sb_bus *bus, sb_transport t, uint32_t baud);
/* Drops what waits unread, then writes frame in one write. */
sb_error sb_send(sb_bus *bus, const uint8_t *frame, size_t len);
/* The next answer of packet code from servo (-1: any) by deadline_us (bus
 * clock); other frames skipped. content: SB_ANSWER_CONTENT_MAX bytes. Of a
 * servo given, a frame that does not fit the packet (the wrong length for
 * a fixed-size answer, else one that does not decode: a frame inside the
 * answer) is skipped too; if only such came, SB_E_BAD_ANSWER on it. */
sb_error sb_receive(sb_bus *bus, uint8_t code, int servo, uint64_t deadline_us, uint8_t *content, size_t *len);
/* sb_send the frame in bus->tx (len bytes), then sb_receive within timeout_us. */
sb_error sb_request(sb_bus *bus, size_t len, uint8_t code, int servo, uint8_t *content, size_t *clen);
/* The same for an answer about item (its content's second byte: ReadData's
 * and WriteData's data_id); answers about another are skipped, and if only
 * they came, SB_E_BAD_ANSWER on "data_id" (value: theirs, least = most: item). */
sb_error sb_request_item(sb_bus *bus, size_t len, uint8_t code, int servo, int item, uint8_t *content, size_t *clen);
/* The bytes of a packet's answer frame (its fields fixed), or 0. */
size_t sb_answer_frame_size(uint8_t code);

/* ---- SyncCommand and the Sync Monitor ---------------------------------- */
/* A SyncCommand frame of count records of cmd (a syncable packet), each
 * record_len bytes of records, made by sb_content_<packet>. */
sb_error sb_sync_frame(uint8_t cmd, const uint8_t *records, size_t record_len, size_t count, uint8_t *frame,
                       size_t cap, size_t *len);
sb_error sb_sync_command(sb_bus *bus, uint8_t cmd, const uint8_t *records, size_t record_len, size_t count);
/* Monitors every servo of ids with one request; their answers as they come.
 * got[k] says whether ids[k] answered; an error names the first that did
 * not (the others' states are kept). Each answer is waited for as long as
 * the wire takes: its bytes at the baud rate, the servos' turnaround, a
 * silent servo's SB_SYNC_SILENCE_US before the next takes its turn, and
 * answer_margin_us; a silent servo costs one such slot, not a time-out.
 * Only an answer that takes a listed servo's turn moves that schedule (a
 * frame of a servo not listed, or whose turn has passed, does not), and
 * however the line babbles the round ends by the request's end plus count
 * times (such a slot + SB_SYNC_SILENCE_US). Answers come in the list's
 * order: an answer of ids[k] drops any taken of a later servo (a previous
 * round's, late); a frame naming a servo that answered, or one before a
 * servo that answered in its turn, is ignored (a frame made of two
 * answers' bytes); a frame of the wrong length does not take the turn
 * while the answer may yet end (SB_E_BAD_ANSWER on "length" if it
 * does not). An ID listed twice, or the broadcast ID, is
 * refused before anything is sent (sb_check_ids); got[] is all false after
 * any error before the answers (a refusal, a link error). */
sb_error sb_sync_monitor(sb_bus *bus, const uint8_t *ids, size_t count, sb_monitor_answer *states, bool *got);
/* The same after a frame already sent (a robot loop's burst). */
sb_error sb_sync_monitor_answers(sb_bus *bus, const uint8_t *ids, size_t count, sb_monitor_answer *states,
                                 bool *got);

/* ---- the stream of setpoints (StreamSetpoint) -------------------------- */
typedef struct sb_stream {
    uint8_t ids[SB_MAX_SERVOS];
    size_t count;
    uint16_t period_ms;
    uint32_t sent;
    int32_t last[SB_MAX_SERVOS]; /* the last angle sent (0.1 deg) */
    int32_t angle_min[SB_MAX_SERVOS], angle_max[SB_MAX_SERVOS]; /* each servo's limits (0.1 deg) */
} sb_stream;
/* period_ms: 1..1000, item 69's range (stream_period_ms) but for its 0
 * (off); else SB_E_USAGE on "period_ms". Keep it at most half of each
 * servo's watchdog_ms (item 64), which servobus does not read. */
sb_error sb_stream_init(sb_stream *s, const uint8_t *ids, size_t count, uint16_t period_ms);
/* The next setpoints' frame: angles in 0.1 deg, velocities in 0.1 deg/s
 * (NULL: from the last two setpoints). An angle beyond its field or its
 * servo's limits, a step faster than the servo moves, a velocity beyond
 * the field's range: SB_E_RANGE naming the servo, nothing made. The stream
 * then counts the frame sent: if it is not, put back a copy of s taken
 * before (sb_loop_cycle does), or the next step is checked from a setpoint
 * the servos never got. */
sb_error sb_stream_frame(sb_stream *s, const int32_t *angles, const int16_t *velocities, uint8_t *frame,
                         size_t cap, size_t *len);
/* As sb_stream_frame, stamped at_ms: the moment on the host's clock (ms;
 * the frame keeps its low 16 bits) the setpoints are for. Each servo plays
 * them 3/2 period after that moment, so a frame sent late or early by less
 * than that moves nothing (docs/streaming.md, "On the host's timeline").
 * sb_stream_frame stamps the frame's place on the period's grid instead
 * (sent * period_ms): right only for a caller that keeps that grid. */
sb_error sb_stream_frame_at(sb_stream *s, const int32_t *angles, const int16_t *velocities, uint32_t at_ms,
                            uint8_t *frame, size_t cap, size_t *len);

/* ---- the robot loop ----------------------------------------------------- */
/* A cycle: one SyncCommand of setpoints and one Sync Monitor in one write,
 * then every servo's state (got[] all false if the setpoints are refused or
 * the link fails; a failed write leaves the stream as it was). Called once
 * per period_ms: the setpoints' speeds count on it; each cycle is stamped
 * with the bus clock's now (sb_stream_frame_at), so a late call is played
 * at the time it was made, not one period after the last. On a
 * loop sb_loop_init refused: SB_E_USAGE on "loop", nothing sent. */
typedef struct sb_loop {
    sb_bus *bus;
    sb_stream stream;
    uint8_t monitor[10u + SB_MAX_SERVOS]; /* what sb_sync_frame asks: 7 + its content */
    size_t monitor_len;
    uint32_t cycles;
    uint32_t missed; /* states that did not come */
    uint64_t started_us;
} sb_loop;
/* As sb_stream_init, and a period shorter than the cycle's bytes on the
 * wire at bus->baud (sb_cycle_bytes; least: the shortest, in whole ms) or a
 * bus at baud 0 is SB_E_USAGE (servoctl's RobotLoop, check_wire). */
sb_error sb_loop_init(sb_loop *l, sb_bus *bus, const uint8_t *ids, size_t count, uint16_t period_ms);
sb_error sb_loop_cycle(sb_loop *l, const int32_t *angles, const int16_t *velocities, sb_monitor_answer *states,
                       bool *got);
/* A cycle's bytes on the wire (both requests and every answer), and the
 * most cycles a second the wire carries at baud (servoctl's loop_rate.py). */
size_t sb_cycle_bytes(size_t count);
double sb_wire_limit_hz(size_t count, uint32_t baud);
/* Cycles a second since the first cycle, on the bus clock. */
double sb_loop_rate_hz(const sb_loop *l);

/* ---- a microcontroller's UART: a pair of callbacks ---------------------- */
/* send: the bytes onto the bus (returns once they are sent or queued);
 * recv: the next received byte, or -1 if none; now_us: a microsecond clock. */
typedef struct sb_uart {
    void (*send)(void *ctx, const uint8_t *data, size_t len);
    int (*recv)(void *ctx);
    uint64_t (*now_us)(void *ctx);
    void *ctx;
} sb_uart;
sb_transport sb_uart_transport(sb_uart *uart);

#ifdef __cplusplus
}
#endif

#endif
