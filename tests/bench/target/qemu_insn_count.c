/* QEMU TCG plugin: counts the guest instructions executed between two
 * marker addresses, region after region.
 *
 *   -plugin libqemu_insn_count.so,begin=0xADDR,end=0xADDR,out=FILE
 *
 * Every instruction adds one to a counter (an inline op, no call); the
 * first instruction of each marker function takes a snapshot. At exit the
 * counts of the regions, in order, go to FILE, one per line. A guest that
 * exits through semihosting ends the process without QEMU's own plugin
 * exit hooks, so the file is written from the C library's atexit. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qemu_plugin_api.h"

PLUGIN_EXPORT int qemu_plugin_version = 1;

enum { MAX_REGIONS = 256 };

static uint64_t executed;
static uint64_t begun_at;
static uint64_t regions[MAX_REGIONS];
static unsigned region_count;
static uint64_t begin_addr, end_addr;
static char out_path[512];

static void on_begin(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    (void)userdata;
    begun_at = executed;
}

static void on_end(unsigned int vcpu, void *userdata)
{
    (void)vcpu;
    (void)userdata;
    if (region_count < MAX_REGIONS) {
        regions[region_count++] = executed - begun_at;
    }
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        uint64_t at = qemu_plugin_insn_vaddr(insn);
        if (at == begin_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_begin, QEMU_PLUGIN_CB_NO_REGS, NULL);
        } else if (at == end_addr) {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_end, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        qemu_plugin_register_vcpu_insn_exec_inline(insn, QEMU_PLUGIN_INLINE_ADD_U64, &executed, 1);
    }
}

static void write_counts(void)
{
    FILE *f = fopen(out_path, "w");
    if (f == NULL) {
        perror(out_path);
        return;
    }
    fprintf(f, "total %" PRIu64 "\n", executed);
    for (unsigned i = 0; i < region_count; i++) {
        fprintf(f, "%" PRIu64 "\n", regions[i]);
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
        }
    }
    if (begin_addr == 0 || end_addr == 0 || out_path[0] == '\0') {
        fprintf(stderr, "qemu_insn_count: needs begin=, end= and out=\n");
        return 1;
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    atexit(write_counts);
    return 0;
}
