/* The cross-check's C side (tools/tests/test_servobus_crosscheck.py): one
 * line in, one line out, on stdin and stdout.
 *   req CODE V...   a request frame from the fields' values    -> ok HEX | err STATUS SERVO FIELD
 *   ans CODE V...   an answer frame                            -> the same
 *   dreq HEX        a request frame's fields                   -> ok CODE V... | err STATUS SERVO FIELD
 *   dans HEX        an answer frame's fields                   -> the same
 * A value is a decimal number, or x:HEX for bytes (a user area, a block). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "servobus/servobus.h"

#define MAX_FIELDS 16
#define MAX_BYTES 1024

static uint8_t blobs[MAX_FIELDS][MAX_BYTES];

static size_t unhex(const char *s, uint8_t *out, size_t cap)
{
    size_t n = 0;
    while (s[0] != '\0' && s[1] != '\0' && n < cap) {
        unsigned b = 0;
        if (sscanf(s, "%2x", &b) != 1)
            break;
        out[n++] = (uint8_t)b;
        s += 2;
    }
    return n;
}

static void put_hex(const uint8_t *b, size_t n)
{
    for (size_t k = 0; k < n; k++)
        printf("%02x", b[k]);
}

static void put_error(sb_error e)
{
    printf("err %d %d %s\n", (int)e.status, (int)e.servo, e.field != NULL ? e.field : "-");
}

static void encode(bool request, char *args)
{
    sb_value v[MAX_FIELDS];
    size_t count = 0, len = 0;
    uint8_t frame[MAX_BYTES + 16];
    char *tok = strtok(args, " \n");
    uint8_t code = (uint8_t)strtol(tok != NULL ? tok : "0", NULL, 10);
    memset(v, 0, sizeof v);
    while ((tok = strtok(NULL, " \n")) != NULL && count < MAX_FIELDS) {
        if (strncmp(tok, "x:", 2) == 0) {
            v[count].len = unhex(tok + 2, blobs[count], MAX_BYTES);
            v[count].bytes = blobs[count];
        } else {
            v[count].n = strtoll(tok, NULL, 10);
        }
        count++;
    }
    sb_error e = request ? sb_encode_request(code, v, count, frame, sizeof frame, &len)
                         : sb_encode_answer(code, v, count, frame, sizeof frame, &len);
    if (e.status != SB_OK) {
        put_error(e);
        return;
    }
    printf("ok ");
    put_hex(frame, len);
    printf("\n");
}

static void decode(bool request, const char *hex)
{
    uint8_t frame[MAX_BYTES + 16];
    sb_value v[MAX_FIELDS];
    size_t n = unhex(hex, frame, sizeof frame), head, clen;
    const sb_packet_desc *p;
    sb_error e = sb_ok();
    if (n < 5 || frame[0] != (request ? SB_REQUEST_HEADER_0 : SB_RESPONSE_HEADER_0) ||
        frame[1] != (request ? SB_REQUEST_HEADER_1 : SB_RESPONSE_HEADER_1)) {
        printf("err frame\n");
        return;
    }
    head = frame[3] == SB_EXTENDED_LENGTH ? 6u : 4u;
    clen = head == 6u ? (size_t)(frame[4] | frame[5] << 8) : frame[3];
    if (n != head + clen + 1u || sb_checksum(frame, n - 1u) != frame[n - 1u]) {
        printf("err frame\n");
        return;
    }
    p = sb_packet(frame[2]);
    if (p == NULL) {
        printf("err packet\n");
        return;
    }
    size_t count = request ? p->request_count : p->answer_count;
    e = request ? sb_decode_request(frame[2], frame + head, clen, v, count)
                : sb_decode_answer(frame[2], frame + head, clen, v, count);
    if (e.status != SB_OK) {
        put_error(e);
        return;
    }
    printf("ok %u", frame[2]);
    for (size_t k = 0; k < count; k++) {
        uint8_t type = request ? p->request[k].type : p->answer[k].type;
        if (type == SB_USER_AREA || type == SB_BYTES) {
            printf(" x:");
            put_hex(v[k].bytes, v[k].len);
        } else if (type == SB_ITEM && v[k].len == 0) {
            printf(" -");
        } else {
            printf(" %lld", (long long)v[k].n);
        }
    }
    printf("\n");
}

int main(void)
{
    static char line[4 * MAX_BYTES];
    while (fgets(line, sizeof line, stdin) != NULL) {
        char *rest = strchr(line, ' ');
        if (rest == NULL)
            continue;
        *rest++ = '\0';
        rest[strcspn(rest, "\n")] = '\0';
        if (strcmp(line, "req") == 0 || strcmp(line, "ans") == 0)
            encode(line[0] == 'r', rest);
        else if (strcmp(line, "dreq") == 0 || strcmp(line, "dans") == 0)
            decode(line[1] == 'r', rest);
        else
            printf("err usage\n");
        fflush(stdout);
    }
    return 0;
}
