/* QEMU TCG plugin: counts the guest instructions executed between two
 * marker addresses, region after region, and models their cycles.
 *
 *   -plugin libqemu_insn_count.so,begin=0xADDR,end=0xADDR,out=FILE[,core=m3|m0|m0p][,ws=N]
 *           [,line=BYTES][,profile=PFILE]
 *
 * Instructions: every instruction adds one to a counter (an inline op, no
 * call); the first instruction of each marker function takes a snapshot.
 *
 * Cycles (a model, thumb_cycles.h for the instruction costs): each
 * translation block adds its instructions' own costs when it runs, and a
 * block that does not start where the last one ended follows a taken
 * branch: + the pipeline refill (thumb_refill: 2 on the M3, TRM 18.2: "P",
 * 1-3, and on the M0, whose taken branch is 3 cycles; 1 on the M0+, whose
 * is 2) + the flash's wait states (ws; STM32F1 at 72 MHz: 2, RM0008 3.3.3;
 * STM32F030 at 48 MHz: 1, RM0360 3.5.1; STM32G0 at 64 MHz: 2, RM0444
 * 3.3.4), which the prefetch buffer cannot hide after a jump. A literal
 * load from flash pays the wait states too, and straight-line code runs no
 * faster than the prefetch buffer fills: one flash line per 1 + ws cycles
 * (line: the F1's flash reads 64 bits, RM0008 3.3.3: 8 bytes; the F0's 32,
 * RM0360 3.2.1: 4; the G0's 64, RM0444 3.3.1: 8). The G0's instruction
 * cache (ICEN, which the firmware sets) is not modelled: a jump into code
 * it holds is charged the wait states all the same.
 *
 * With profile=PFILE, each region's blocks go to PFILE as they end:
 * "region start_address instructions block_length" lines, for a breakdown
 * by function or by source line.
 *
 * At exit, "total I C" and then "I C" per region go to FILE. A guest that
 * exits through semihosting ends the process without QEMU's plugin exit
 * hooks, so the file is written from the C library's atexit. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench/target/qemu_plugin_api.h"
#include "bench/target/thumb_cycles.h"

PLUGIN_EXPORT int qemu_plugin_version = 1;

enum { MAX_REGIONS = 8192, MAX_BLOCKS = 65536 };

static uint64_t executed, cycles;
static uint64_t begun_at, begun_cycles;
static uint64_t regions[MAX_REGIONS][2];
static unsigned region_count;
static uint64_t begin_addr, end_addr;
static char out_path[512];
static enum core core = CORE_M3;
static unsigned wait_states = 2;
static unsigned line_bytes = 8;
static FILE *profile;
static int in_region;

/* What a translated block costs when it runs; blocks are never freed. */
struct block {
    uint64_t start, end;
    uint32_t cycles;
    uint32_t insns;
    uint64_t hits; /* runs inside the current region, for the profile */
};
static struct block blocks[MAX_BLOCKS];
static unsigned block_count;
static uint64_t last_end;

static void on_begin(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    (void)userdata;
    begun_at = executed;
    begun_cycles = cycles;
    in_region = 1;
}

static void on_end(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    (void)userdata;
    if (region_count < MAX_REGIONS) {
        regions[region_count][0] = executed - begun_at;
        regions[region_count][1] = cycles - begun_cycles;
        region_count++;
    }
    in_region = 0;
    if (profile != NULL) {
        for (unsigned i = 0; i < block_count; i++) {
            if (blocks[i].hits != 0u) {
                fprintf(profile, "%u %#" PRIx64 " %" PRIu64 " %" PRIu32 "\n", region_count - 1u,
                        blocks[i].start, blocks[i].hits * blocks[i].insns, blocks[i].insns);
                blocks[i].hits = 0;
            }
        }
    }
}

static void on_block(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    struct block *b = userdata;
    b->hits += (uint64_t)in_region;
    if (b->start != last_end) {
        cycles += thumb_refill(core) + wait_states; /* after a taken branch */
    }
    cycles += b->cycles;
    last_end = b->end;
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    uint32_t own = 0;
    uint32_t bytes = 0;
    uint64_t end = qemu_plugin_tb_vaddr(tb);
    bool after_ldst = false;
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t at = qemu_plugin_insn_vaddr(insn);
        size_t size = qemu_plugin_insn_size(insn);
        const uint8_t *code = qemu_plugin_insn_data(insn);
        uint16_t hw = (uint16_t)(code[0] | code[1] << 8);
        uint16_t hw2 = size == 4u ? (uint16_t)(code[2] | code[3] << 8) : 0u;
        struct insn_cost c = thumb_cost(core, hw, hw2, (unsigned)size);
        own += c.cycles + (c.literal_load ? wait_states : 0u);
        if (core == CORE_M3 && c.single_ldst && after_ldst && c.cycles > 1u) {
            own -= 1u; /* pipelined behind the previous load or store */
        }
        after_ldst = c.single_ldst;
        bytes += (uint32_t)size;
        end = at + size;
        if (at == begin_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_begin, QEMU_PLUGIN_CB_NO_REGS, NULL);
        } else if (at == end_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_end, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &executed, 1);
    }
    /* Straight-line code runs no faster than the flash fills the prefetch
     * buffer: a line per 1 + ws cycles. */
    uint32_t fetch = (bytes + line_bytes - 1u) / line_bytes * (1u + wait_states);
    if (block_count < MAX_BLOCKS) {
        struct block *b = &blocks[block_count++];
        *b = (struct block){qemu_plugin_tb_vaddr(tb), end, own > fetch ? own : fetch, (uint32_t)n, 0};
        qemu_plugin_register_vcpu_tb_exec_cb(tb, on_block, QEMU_PLUGIN_CB_NO_REGS, b);
    }
}

static void write_counts(void)
{
    if (profile != NULL) {
        fclose(profile);
    }
    FILE *f = fopen(out_path, "w");
    if (f == NULL) {
        perror(out_path);
        return;
    }
    fprintf(f, "total %" PRIu64 " %" PRIu64 "\n", executed, cycles);
    for (unsigned i = 0; i < region_count; i++) {
        fprintf(f, "%" PRIu64 " %" PRIu64 "\n", regions[i][0], regions[i][1]);
    }
    fclose(f);
}

PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc,
                                      char **argv);

PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc,
                                      char **argv)
{
    (void)info;
    for (int i = 0; i < argc; i++) {
        if (strncmp(argv[i], "begin=", 6) == 0) {
            begin_addr = strtoull(argv[i] + 6, NULL, 0) & ~1ull; /* Thumb bit */
        } else if (strncmp(argv[i], "end=", 4) == 0) {
            end_addr = strtoull(argv[i] + 4, NULL, 0) & ~1ull;
        } else if (strncmp(argv[i], "out=", 4) == 0) {
            snprintf(out_path, sizeof out_path, "%s", argv[i] + 4);
        } else if (strcmp(argv[i], "core=m0") == 0) {
            core = CORE_M0;
        } else if (strcmp(argv[i], "core=m0p") == 0) {
            core = CORE_M0P;
        } else if (strncmp(argv[i], "profile=", 8) == 0) {
            profile = fopen(argv[i] + 8, "w");
            if (profile == NULL) {
                perror(argv[i] + 8);
                return 1;
            }
        } else if (strncmp(argv[i], "ws=", 3) == 0) {
            wait_states = (unsigned)strtoul(argv[i] + 3, NULL, 0);
        } else if (strncmp(argv[i], "line=", 5) == 0) {
            line_bytes = (unsigned)strtoul(argv[i] + 5, NULL, 0);
        }
    }
    if (begin_addr == 0 || end_addr == 0 || out_path[0] == '\0' || line_bytes == 0u) {
        fprintf(stderr, "qemu_insn_count: needs begin=, end= and out=\n");
        return 1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    atexit(write_counts);
    return 0;
}
