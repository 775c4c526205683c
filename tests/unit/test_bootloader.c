/* The bootloader's core: the image check, the update packets, and a power
 * cut at every erase and program step of an update. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "bootloader/app_image.h"
#include "bootloader/boot_flow.h"
#include "bootloader/boot_packets.h"
#include "runtime/crc32.h"
#include "protocol/packet_codes.h"
#include "bootloader/slot_write.h"
#include "protocol/wire.h"

#define PAGE 1024u
#define PAGES 8u
#define BASE 0x08001000u
#define BOARD 0x0103u
#define ID 5u

/* The slot's flash, with the STM32F1's rules (erase to 0xFF, program only
 * erased half-words), that loses power at step cut_at (an erase or a
 * program): that step is left half done, nothing after it happens. */
static struct {
    uint8_t mem[PAGES * PAGE];
    long steps;
    long cut_at; /* -1: never */
    bool dead;
    long reads;  /* read() calls */
} chip;

static bool step_survives(void)
{
    if (chip.dead) {
        return false;
    }
    if (chip.steps++ == chip.cut_at) {
        chip.dead = true;
        return false;
    }
    return true;
}

static bool erase_page(void *ctx, uint32_t addr)
{
    (void)ctx;
    uint8_t *page = &chip.mem[addr - BASE];
    if (!step_survives()) {
        if (chip.steps - 1 == chip.cut_at) {
            memset(page, 0xFF, PAGE / 2u); /* cut half way */
        }
        return false;
    }
    memset(page, 0xFF, PAGE);
    return true;
}

static bool program(void *ctx, uint32_t addr, const uint8_t *data)
{
    (void)ctx;
    uint8_t *cell = &chip.mem[addr - BASE];
    if (cell[0] != 0xFFu || cell[1] != 0xFFu) {
        return false;
    }
    if (!step_survives()) {
        if (chip.steps - 1 == chip.cut_at) {
            cell[0] = (uint8_t)(data[0] | 0x0Fu); /* some bits cleared, not all */
        }
        return false;
    }
    cell[0] = data[0];
    cell[1] = data[1];
    return true;
}

static void read(void *ctx, uint32_t addr, uint8_t *dst, uint32_t len)
{
    (void)ctx;
    chip.reads++;
    memcpy(dst, &chip.mem[addr - BASE], len);
}

static const struct hal_flash flash = {
    .page_size = PAGE, .erase_page = erase_page, .write_block = 2, .program = program, .read = read};
static const struct app_slot slot = {.flash = &flash, .base = BASE, .pages = PAGES};
static struct bootloader boot = {.slot = &slot, .board = BOARD, .id = ID};

static void power_on(void)
{
    chip.cut_at = -1;
    chip.dead = false;
    boot.boot_now = 0;
    boot.checked = 0; /* RAM lost: nothing checked yet */
}

static int setup(void **state)
{
    (void)state;
    memset(chip.mem, 0xFF, sizeof chip.mem);
    chip.steps = 0;
    power_on();
    return 0;
}

/* An image of `size` code bytes (seeded), version, for board. */
static size_t make_image(uint8_t *out, uint32_t size, uint16_t version, uint16_t board,
                         unsigned seed)
{
    for (uint32_t i = 0; i < size; i++) {
        out[APP_HEADER_SIZE + i] = (uint8_t)(seed * 31u + i * 7u + (i >> 8));
    }
    app_image_make_header(out, &out[APP_HEADER_SIZE], size, version, board);
    return APP_HEADER_SIZE + size;
}

static struct response last;

static bool request(uint8_t code, const uint8_t *content, uint16_t length)
{
    memset(&last, 0, sizeof last);
    return boot_packet(&boot, code, content, length, &last);
}

static bool erase_page_request(uint16_t page)
{
    uint8_t c[3] = {ID};
    le_put_u16(&c[1], page);
    assert_true(request(PKT_UPDATE_ERASE, c, sizeof c));
    return last.content[1] == 1u;
}

static uint8_t write_request(uint32_t offset, const uint8_t *data, uint16_t n)
{
    uint8_t c[9 + UPDATE_WRITE_MAX] = {ID};
    le_put_u32(&c[1], offset);
    memcpy(&c[5], data, n);
    le_put_u32(&c[5 + n], crc32(data, n));
    assert_true(request(PKT_UPDATE_WRITE, c, (uint16_t)(9u + n)));
    return last.content[2];
}

/* What servoctl update does: erase the slot (the header's page first),
 * write the code, the header's start last. With header_first, a tool that
 * writes in file order: then the image's CRC alone keeps a half-written
 * image from starting. False when a step is refused (the power went). */
static bool update_in_order(const uint8_t *image, size_t size, bool header_first)
{
    for (uint16_t page = 0; page < (size + PAGE - 1u) / PAGE; page++) {
        if (!erase_page_request(page)) {
            return false;
        }
    }
    if (header_first && write_request(0, image, UPDATE_WRITE_MAX) != SLOT_WRITE_OK) {
        return false;
    }
    for (size_t at = UPDATE_WRITE_MAX; at < size; at += UPDATE_WRITE_MAX) {
        uint16_t n = (uint16_t)(size - at < UPDATE_WRITE_MAX ? size - at : UPDATE_WRITE_MAX);
        n = (uint16_t)((n + 1u) & ~1u); /* whole half-words: the image is padded */
        if (write_request((uint32_t)at, &image[at], n) != SLOT_WRITE_OK) {
            return false;
        }
    }
    return header_first || write_request(0, image, UPDATE_WRITE_MAX) == SLOT_WRITE_OK;
}

static bool update(const uint8_t *image, size_t size)
{
    return update_in_order(image, size, false);
}

static void test_an_image_checks_only_when_whole(void **state)
{
    (void)state;
    static uint8_t image[PAGES * PAGE + 16u];
    struct app_image_info info = {.size = 1, .crc = 1, .version = 1, .board = 1};
    assert_int_equal(app_image_check(&slot, BOARD, &info), APP_IMAGE_NO_HEADER);
    /* A refused header tells nothing: UpdateStatus and UpdateVerify answer 0s. */
    assert_int_equal(info.size, 0);
    assert_int_equal(info.version, 0);
    assert_int_equal(info.board, 0);
    size_t n = make_image(image, 3000, 7, BOARD, 1);
    memcpy(chip.mem, image, n);
    assert_int_equal(app_image_check(&slot, BOARD, &info), APP_IMAGE_VALID);
    assert_int_equal(info.version, 7);
    assert_int_equal(info.size, 3000);
    assert_int_equal(app_image_check(&slot, BOARD + 1u, &info), APP_IMAGE_WRONG_BOARD);
    chip.mem[APP_HEADER_SIZE + 2999] ^= 1u; /* one bit of the code */
    assert_int_equal(app_image_check(&slot, BOARD, &info), APP_IMAGE_BAD_CRC);
    chip.mem[APP_HEADER_SIZE + 2999] ^= 1u;
    chip.mem[16] ^= 1u; /* the version, under the header's CRC */
    assert_int_equal(app_image_check(&slot, BOARD, &info), APP_IMAGE_BAD_HEADER);
    chip.mem[16] ^= 1u;
    make_image(image, PAGES * PAGE - APP_HEADER_SIZE + 2u, 7, BOARD, 1); /* larger than the slot */
    memcpy(chip.mem, image, APP_HEADER_SIZE);
    assert_int_equal(app_image_check(&slot, BOARD, &info), APP_IMAGE_BAD_HEADER);
}

static void test_an_update_by_packets(void **state)
{
    (void)state;
    static uint8_t image[PAGES * PAGE];
    size_t n = make_image(image, 5000, 0x0203, BOARD, 2);
    assert_true(update(image, n));
    assert_true(request(PKT_UPDATE_VERIFY, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.length, 14);
    assert_int_equal(last.content[1], APP_IMAGE_VALID);
    assert_int_equal(le_get_u32(&last.content[2]), 5000);
    assert_int_equal(le_get_u16(&last.content[10]), 0x0203);
    assert_true(request(PKT_UPDATE_BOOT, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.content[1], 1);
    assert_true(boot.boot_now);
    assert_memory_equal(chip.mem, image, n);
}

/* The header matches what bootloader/servo_image builds: the same bytes
 * for the same code (tools/tests/test_image.py holds the same vector). */
static void test_the_header_matches_the_tool(void **state)
{
    (void)state;
    uint8_t code[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    uint8_t header[APP_HEADER_SIZE];
    app_image_make_header(header, code, sizeof code, 0x0011, 0x0103);
    assert_int_equal(le_get_u32(&header[12]), 0x3FCA88C5u); /* zlib.crc32(bytes(1..8)) */
    assert_int_equal(le_get_u32(&header[24]), 0x790C7AB0u);
}

static void test_what_the_bootloader_refuses(void **state)
{
    (void)state;
    uint8_t data[16] = {1, 2, 3, 4};
    /* Another ID, broadcast, a wrong length: no answer at all. */
    assert_false(boot_packet(&boot, PKT_UPDATE_VERIFY, (const uint8_t[]){ID + 1u}, 1, &last));
    assert_false(boot_packet(&boot, PKT_UPDATE_VERIFY, (const uint8_t[]){0xFF}, 1, &last));
    assert_false(request(PKT_UPDATE_VERIFY, (const uint8_t[]){ID, 0}, 2));
    assert_false(request(PKT_READ_DATA, (const uint8_t[]){ID, 5}, 2));
    /* Damaged on the wire: nothing written. */
    uint8_t c[9 + 16] = {ID};
    le_put_u32(&c[1], 512);
    memcpy(&c[5], data, 16);
    le_put_u32(&c[21], crc32(data, 16) ^ 1u);
    assert_true(request(PKT_UPDATE_WRITE, c, sizeof c));
    assert_int_equal(last.content[1], 0);
    assert_int_equal(last.content[2], SLOT_WRITE_BAD_CRC);
    assert_int_equal(chip.mem[512], 0xFF);
    /* Beyond the slot, odd offset, odd length, a page past the end. */
    assert_int_equal(write_request(PAGES * PAGE - 2u, data, 4), SLOT_WRITE_OUT_OF_SLOT);
    assert_int_equal(write_request(513, data, 2), SLOT_WRITE_OUT_OF_SLOT);
    assert_int_equal(write_request(512, data, 3), SLOT_WRITE_OUT_OF_SLOT);
    assert_false(erase_page_request(PAGES));
    /* The same bytes again (the host lost the answer): done, nothing
     * programmed twice. Half of them there (a cut): the rest programmed.
     * Other bytes over them (or a block a cut left neither erased nor
     * holding them): refused, nothing programmed; its page is to be erased. */
    assert_int_equal(write_request(512, data, 4), SLOT_WRITE_OK);
    long steps = chip.steps;
    assert_int_equal(write_request(512, data, 4), SLOT_WRITE_OK);
    assert_int_equal(chip.steps, steps);
    assert_int_equal(write_request(520, data, 2), SLOT_WRITE_OK);
    assert_int_equal(write_request(520, data, 4), SLOT_WRITE_OK);
    assert_memory_equal(&chip.mem[520], data, 4);
    data[1] ^= 0x10u;
    steps = chip.steps;
    assert_int_equal(write_request(512, data, 4), SLOT_WRITE_NOT_ERASED);
    assert_int_equal(chip.steps, steps);
    /* Nothing valid in the slot: no boot. */
    assert_true(request(PKT_UPDATE_BOOT, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.content[1], 0);
    assert_false(boot.boot_now);
}

static void test_ping_and_status_find_the_bootloader(void **state)
{
    (void)state;
    assert_true(request(PKT_PING, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.code, PKT_PING);
    assert_int_equal(last.length, 1);
    assert_int_equal(last.content[0], ID);
    assert_true(request(PKT_UPDATE_STATUS, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.length, 16);
    assert_int_equal(last.content[1], 1); /* the bootloader answers */
    assert_int_equal(le_get_u16(&last.content[2]), BOOTLOADER_VERSION);
    assert_int_equal(last.content[4], APP_IMAGE_NO_HEADER);
    assert_int_equal(le_get_u16(&last.content[9]), PAGE);
    assert_int_equal(le_get_u16(&last.content[11]), PAGES);
    assert_int_equal(last.content[13], 2);
    assert_int_equal(le_get_u16(&last.content[14]), UPDATE_WRITE_MAX);
}

/* UpdateStatus answers from the slot's last check (a CRC of the whole
 * image: tens of ms on an M0), checked again only after an erase or a
 * write changed the slot. */
static void test_status_answers_from_the_last_check(void **state)
{
    (void)state;
    static uint8_t image[2u * PAGE];
    size_t size = make_image(image, 2u * PAGE - APP_HEADER_SIZE, 0x0203, BOARD, 4);
    assert_true(update(image, size));
    assert_true(request(PKT_UPDATE_STATUS, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.content[4], APP_IMAGE_VALID);
    assert_int_equal(le_get_u16(&last.content[5]), 0x0203);
    long reads = chip.reads;
    assert_true(request(PKT_UPDATE_STATUS, (const uint8_t[]){ID}, 1));
    assert_int_equal(chip.reads, reads); /* the slot not read again */
    assert_int_equal(last.content[4], APP_IMAGE_VALID);
    memset(&chip.mem[PAGE], 0, 4); /* not through the bootloader: not seen */
    assert_true(request(PKT_UPDATE_STATUS, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.content[4], APP_IMAGE_VALID);
    assert_true(request(PKT_UPDATE_VERIFY, (const uint8_t[]){ID}, 1)); /* Verify reads it all */
    assert_int_equal(last.content[1], APP_IMAGE_BAD_CRC);
    assert_true(request(PKT_UPDATE_STATUS, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.content[4], APP_IMAGE_BAD_CRC);
    assert_true(erase_page_request(0));
    assert_true(request(PKT_UPDATE_STATUS, (const uint8_t[]){ID}, 1));
    assert_int_equal(last.content[4], APP_IMAGE_NO_HEADER);
}

/* From an old image to a new one, the power cut at every erase and program
 * step in turn. After each cut the slot holds the new image whole, or
 * nothing the bootloader would start (it stays, and the update runs again
 * from the start, to the new image): it never starts half an image. */
static void test_a_power_cut_at_every_step_never_bricks(void **state)
{
    (void)state;
    static uint8_t old_image[PAGES * PAGE], new_image[PAGES * PAGE];
    size_t old_n = make_image(old_image, 1800, 1, BOARD, 3);
    size_t new_n = make_image(new_image, 2600, 2, BOARD, 4);
    memcpy(chip.mem, old_image, old_n);
    chip.steps = 0;
    assert_true(update(new_image, new_n));
    const long steps = chip.steps;
    long programmed = 0; /* a half-word of 0xFFFF is already what erased flash holds */
    for (size_t i = 0; i < new_n; i += 2u) {
        programmed += new_image[i] != 0xFFu || new_image[i + 1u] != 0xFFu;
    }
    assert_int_equal(steps, 3 + programmed); /* 3 erases, the half-words */
    unsigned stayed = 0;
    unsigned started_new = 0;
    for (long cut = 0; cut < steps; cut++) {
        memset(chip.mem, 0xFF, sizeof chip.mem);
        memcpy(chip.mem, old_image, old_n);
        chip.steps = 0;
        chip.cut_at = cut;
        chip.dead = false;
        assert_false(update(new_image, new_n));
        power_on();
        struct app_image_info info;
        enum app_image_verdict v = app_image_check(&slot, BOARD, &info);
        struct boot_flow flow;
        boot_flow_start(&flow, v == APP_IMAGE_VALID, 0);
        if (v == APP_IMAGE_VALID) {
            /* Whole: the new image once its header's checked bytes are in
             * (the steps left write padding that is 0xFF anyway). */
            assert_int_equal(info.version, 2);
            assert_memory_equal(chip.mem, new_image, new_n);
            assert_int_equal(boot_flow_step(&flow, BOOT_LISTEN_MS * 1000u), BOOT_START_APP);
            started_new++;
        } else {
            stayed++;
            assert_int_equal(boot_flow_step(&flow, 60000u * 1000u), BOOT_STAY);
            assert_true(update(new_image, new_n)); /* the recovery */
            assert_int_equal(app_image_check(&slot, BOARD, &info), APP_IMAGE_VALID);
            assert_int_equal(info.version, 2);
        }
    }
    /* The first step already erases the old header: no cut starts the old
     * image. The last write holds bytes 0-23, all under the header's CRC,
     * so no cut before its last step starts the new one either. */
    assert_int_equal(started_new, 0);
    assert_int_equal(stayed + started_new, steps);
}

/* Written in file order, header first: a cut anywhere before the last
 * half-word leaves an image whose CRC fails, which never starts. */
static void test_the_image_crc_guards_any_write_order(void **state)
{
    (void)state;
    static uint8_t image[PAGES * PAGE];
    size_t n = make_image(image, 2000, 3, BOARD, 5);
    chip.steps = 0;
    assert_true(update_in_order(image, n, true));
    const long steps = chip.steps;
    for (long cut = 0; cut < steps; cut++) {
        memset(chip.mem, 0xFF, sizeof chip.mem);
        chip.steps = 0;
        chip.cut_at = cut;
        chip.dead = false;
        assert_false(update_in_order(image, n, true));
        power_on();
        struct app_image_info info;
        enum app_image_verdict v = app_image_check(&slot, BOARD, &info);
        /* The last code half-words may be 0xFF already (the image's padding). */
        if (v == APP_IMAGE_VALID) {
            assert_memory_equal(chip.mem, image, n);
        }
    }
}

static void test_the_boot_decision(void **state)
{
    (void)state;
    struct boot_flow f;
    boot_flow_start(&f, true, 0);
    assert_int_equal(boot_flow_step(&f, 0), BOOT_WAIT);
    assert_int_equal(boot_flow_step(&f, BOOT_LISTEN_MS * 1000u - 1u), BOOT_WAIT);
    assert_int_equal(boot_flow_step(&f, BOOT_LISTEN_MS * 1000u), BOOT_START_APP);
    boot_flow_start(&f, true, 0);
    boot_flow_heard(&f); /* a request in the window: stay */
    assert_int_equal(boot_flow_step(&f, 10u * BOOT_LISTEN_MS * 1000u), BOOT_STAY);
    boot_flow_start(&f, true, BOOT_STAY_MAGIC); /* UpdateEnter */
    assert_int_equal(boot_flow_step(&f, 0), BOOT_STAY);
    boot_flow_start(&f, false, 0); /* nothing valid to start */
    assert_int_equal(boot_flow_step(&f, 10u * BOOT_LISTEN_MS * 1000u), BOOT_STAY);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_an_image_checks_only_when_whole, setup),
        cmocka_unit_test_setup(test_an_update_by_packets, setup),
        cmocka_unit_test_setup(test_the_header_matches_the_tool, setup),
        cmocka_unit_test_setup(test_what_the_bootloader_refuses, setup),
        cmocka_unit_test_setup(test_ping_and_status_find_the_bootloader, setup),
        cmocka_unit_test_setup(test_status_answers_from_the_last_check, setup),
        cmocka_unit_test_setup(test_a_power_cut_at_every_step_never_bricks, setup),
        cmocka_unit_test_setup(test_the_image_crc_guards_any_write_order, setup),
        cmocka_unit_test_setup(test_the_boot_decision, setup),
    };
    return cmocka_run_group_tests_name("bootloader", tests, NULL, NULL);
}
