#!/usr/bin/env python3
"""Runs the ARM builds of the benchmarks under qemu-system-arm with the
instruction-counting plugin and prints Thumb-2 instruction counts per region
for the Cortex-M3, the Cortex-M0 and the Cortex-M0+, beside their budgets.

    python3 tests/bench/target/run_target_bench.py [--check] [--json FILE] [--profile REGION]

Needs: cmake --build --preset target-bench-m3, --preset target-bench-m0,
--preset target-bench-m0p, and the host preset's
build/host/tests/libqemu_insn_count.so. QEMU has no Cortex-M0+: its image
(the same ARMv6-M instruction set) runs on QEMU's cortex-m0, and the
plugin's model is the M0+'s.

Instructions are exact (QEMU's translator, one count per guest
instruction), less the markers' own cost (the region "overhead"). The
plugin is checked first: 100 more iterations of a 2-instruction loop must
count exactly 200 more instructions. QEMU runs with -icount shift=0: its
clock follows the instruction count, so the SysTick interrupts fall at the
same instructions every run, never where the host's load puts them.
Cycles are the plugin's model
(qemu_insn_count.c, thumb_cycles.h: ARM's timing tables with the M3's
load pipelining, the STM32F1 flash at 2 wait states for the M3 at 72 MHz,
the STM32F030's at 1 wait state for the M0 at 48 MHz, the STM32G031's at 2
for the M0+ at 64 MHz), an estimate, not a measurement."""
import argparse
import bisect
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
PLUGIN = ROOT / "build/host/tests/libqemu_insn_count.so"
CPUS = {"cortex-m3": ROOT / "build/target-bench-m3/bench", "cortex-m0": ROOT / "build/target-bench-m0/bench",
        "cortex-m0plus": ROOT / "build/target-bench-m0p/bench"}
# QEMU 7.2 has no cortex-m0plus: the M0+'s image runs on its cortex-m0
# (ARMv6-M both; the instruction counts are the image's, the cycles the
# plugin's M0+ model).
QEMU_CPU = {"cortex-m3": "cortex-m3", "cortex-m0": "cortex-m0", "cortex-m0plus": "cortex-m0"}
SHORT = {"cortex-m3": "M3", "cortex-m0": "M0", "cortex-m0plus": "M0+"}
# The plugin's cycle model per core: its cost table and the flash's wait states.
# The F103 at 72 MHz: 2 wait states, 64-bit flash lines (RM0008 3.3.3); the
# F030 at 48 MHz: 1 wait state (RM0360 3.5.1, the FLASH_ACR_LATENCY_1 the
# firmware sets), 32-bit lines (RM0360 3.2.1); the G031 at 64 MHz: 2 wait
# states in range 1 (RM0444 3.3.4, the LATENCY_2 its board_io.c sets),
# 64-bit lines (RM0444 3.3.1: 72-bit cells, 64 data and 8 ECC bits); all
# with the prefetch on. The G0's instruction cache, which its board also
# turns on (ICEN), is not modelled, as the F0 and F1 have none.
MODEL = {"cortex-m3": "core=m3,ws=2,line=8", "cortex-m0": "core=m0,ws=1,line=4",
         "cortex-m0plus": "core=m0p,ws=2,line=8"}
CLOCK_MHZ = {"cortex-m3": 72, "cortex-m0": 48, "cortex-m0plus": 64}
KNOWN_LOOP = 200  # 100 more iterations of a 2-instruction loop
# Budgets, in instructions or modelled us, per CPU (docs/benchmark.md).
# Each fails the run (--check) when exceeded. The M0+ runs the M0's
# instruction set and has its budgets; its image plans jerk-limited moves
# (not size first), within 3500.
BUDGETS = {
    "cortex-m3": {"rx_per_byte": 40, "tick": 300, "servo_tick": 450, "plan": 1000, "plan_jerk": 1500},
    "cortex-m0": {"servo_tick": 1000, "plan": 2500},
    "cortex-m0plus": {"servo_tick": 1000, "plan": 2500, "plan_jerk": 3500},
}
RESPONSE_BUDGET_US = {"cortex-m3": 20, "cortex-m0": 30, "cortex-m0plus": 30}
# A write that changes the user area is answered once its record is
# programmed: this budget is the CPU's part; the flash's own
# 24 half-words x 40-70 us (DS5319) come on top (docs/decisions.md).
DURABLE_WRITE_BUDGET_US = {"cortex-m3": 200, "cortex-m0": 600, "cortex-m0plus": 600}
# A Sync Monitor round at 1 Mbaud: its first answer within 2 byte times of
# the request's last stop bit, each later one within 2 of the one before
# (docs/sleep.md, "The first answer").
BYTE_US = 10
TURNAROUND_BUDGET_US = 2 * BYTE_US
TURNAROUNDS = ("first_answer", "first_answer_of_two", "next_answer")
# The M0 and M0+ hand a Sync Monitor's first answer to the UART with its header
# and ID written, and builds the rest behind them (servo.c, send_ahead):
# the DMA takes the content's second byte 4 byte times after the start.
# The build must end within 3, a byte time left for interrupts.
BUILD_BEHIND_BUDGET_US = 3 * BYTE_US
DURABLE_WRITES = ("answer_write_data", "answer_write_batch", "answer_reset_user_data",
                  "answer_write_control_response", "answer_write_control_response_off")


def budget_of(cpu: str, key: str):
    """(limit, unit) of key on cpu, or None."""
    if key in BUDGETS[cpu]:
        return BUDGETS[cpu][key], "instr"
    if key in TURNAROUNDS:
        return TURNAROUND_BUDGET_US, "us"
    if key == "sync_first_build":
        return BUILD_BEHIND_BUDGET_US, "us"
    if key in DURABLE_WRITES:
        return DURABLE_WRITE_BUDGET_US[cpu], "us + flash"
    if key.startswith("answer_"):
        return RESPONSE_BUDGET_US[cpu], "us"
    return None


def judge(cpu: str, key: str, instructions: float, cycles: float) -> tuple:
    """(mark for the table, over: bool)."""
    budget = budget_of(cpu, key)
    if budget is None:
        return "", False
    limit, unit = budget
    value = instructions if unit == "instr" else cycles / CLOCK_MHZ[cpu]
    mark = f"{limit} {unit}"
    if value <= limit:
        return mark, False
    return mark + " OVER", True


def symbol(elf: Path, name: str) -> int:
    out = subprocess.run(["arm-none-eabi-nm", str(elf)], capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] == name:
            return int(parts[0], 16)
    raise SystemExit(f"run_target_bench: {elf} has no {name}")


def functions(elf: Path) -> list:
    """[(start, end, name)] of the image's functions, by address."""
    out = subprocess.run(["arm-none-eabi-nm", "-S", "--defined-only", str(elf)],
                         capture_output=True, text=True, check=True).stdout
    funcs = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tTwW":
            start = int(parts[0], 16) & ~1
            funcs.append((start, start + int(parts[1], 16), parts[3]))
    return sorted(funcs)


def instruction_lines(elf: Path) -> dict:
    """{instruction address: "file:line"} from the disassembly with line numbers."""
    out = subprocess.run(["arm-none-eabi-objdump", "-d", "-l", "--no-show-raw-insn", str(elf)],
                         capture_output=True, text=True, check=True).stdout
    where, lines = "?", {}
    for text in out.splitlines():
        m = re.match(r"^(/\S+):(\d+)", text)
        if m:
            where = f"{Path(m.group(1)).name}:{m.group(2)}"
            continue
        m = re.match(r"^\s+([0-9a-f]+):\s", text)
        if m:
            lines[int(m.group(1), 16)] = where
    return lines


def print_profile(elf: Path, names: list, profile_file: Path, region: str, by_line: bool) -> None:
    """Instructions of one region per function (or per source line), self only."""
    if region not in names:
        return
    indices = {i for i, name in enumerate(names) if name == region}
    funcs = functions(elf)
    addresses = sorted(instruction_lines(elf).items()) if by_line else []
    starts = [a for a, _ in addresses]
    per_key = {}
    for line in profile_file.read_text().splitlines():
        r, start, count, length = line.split()[:4]
        if int(r) not in indices:
            continue
        addr = int(start, 16)
        if not by_line:
            name = next((n for s, e, n in funcs if s <= addr < e), f"{addr:#x}")
            per_key[name] = per_key.get(name, 0) + int(count)
            continue
        # A block's instructions each ran count / length times.
        hits = int(count) // int(length)
        first = bisect.bisect_left(starts, addr)
        for _, where in addresses[first:first + int(length)]:
            per_key[where] = per_key.get(where, 0) + hits
    total = sum(per_key.values())
    print(f"profile of {region} in {elf.name}: {total} instructions, self, "
          f"by {'source line' if by_line else 'function'}")
    for name, count in sorted(per_key.items(), key=lambda kv: -kv[1]):
        print(f"  {count:>10} {100 * count / total:5.1f} %  {name}")


# The harness: the benchmarks' own code (their loops, the port wrappers
# around the real drivers, the markers) and the HAL and flash doubles. Its
# instructions come off every region; the firmware's calls into it stay in.
HARNESS_FILES = ("bench_protocol.c", "bench_motion.c", "bench_region_target.c", "hal_double.c",
                 "flash_double.c", "frames.c", "ideal_encoder.h")


def harness_functions(elf: Path) -> list:
    """[(start, end)] of the functions the harness files define."""
    out = subprocess.run(["arm-none-eabi-nm", "-S", "-l", "--defined-only", str(elf)],
                         capture_output=True, text=True, check=True).stdout
    spans = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) >= 5 and parts[2] in "tT" and Path(parts[4].rsplit(":", 1)[0]).name in HARNESS_FILES:
            start = int(parts[0], 16) & ~1
            spans.append((start, start + int(parts[1], 16)))
    return spans


def harness_share(elf: Path, names: list, profile_file: Path) -> dict:
    """{region: instructions run inside the harness's own functions}."""
    spans = harness_functions(elf)
    if not spans:
        raise SystemExit(f"run_target_bench: {elf.name} has no line information for the harness")
    share = {}
    for line in profile_file.read_text().splitlines():
        r, start, count = line.split()[:3]
        addr = int(start, 16)
        if any(s <= addr < e for s, e in spans):
            share[int(r)] = share.get(int(r), 0) + int(count)
    return share


def run(elf: Path, cpu: str, profile_region: str = "", by_line: bool = False) -> tuple:
    """{region: (instructions, cycles) of the firmware alone}, and the stats lines."""
    with tempfile.TemporaryDirectory() as tmp:
        counts_file = Path(tmp) / "counts.txt"
        profile_file = Path(tmp) / "profile.txt"
        plugin = (f"{PLUGIN},begin={symbol(elf, 'bench_marker_begin'):#x},"
                  f"end={symbol(elf, 'bench_marker_end'):#x},out={counts_file},{MODEL[cpu]}"
                  f",profile={profile_file}")
        proc = subprocess.run(
            ["qemu-system-arm", "-M", "lm3s6965evb", "-cpu", QEMU_CPU[cpu], "-nographic",
             "-semihosting-config", "enable=on,target=native", "-icount", "shift=0", "-kernel", str(elf), "-plugin", plugin],
            capture_output=True, text=True, timeout=600)
        if proc.returncode != 0:
            raise SystemExit(f"run_target_bench: {elf.name} on {cpu} failed: {proc.stderr.strip()}")
        lines = counts_file.read_text().splitlines()
        names = [line.split()[1] for line in proc.stdout.splitlines() if line.startswith("region ")]
        if profile_region:
            print_profile(elf, names, profile_file, profile_region, by_line)
        harness = harness_share(elf, names, profile_file)
    counts = [tuple(int(x) for x in line.split()) for line in lines[1:]]  # after "total I C"
    stats = dict(line.split() for line in proc.stdout.splitlines()
                 if len(line.split()) == 2 and not line.startswith("region "))
    stats["packets"] = [tuple(line.split()[1:]) for line in proc.stdout.splitlines()
                        if line.startswith("packet ")]
    if len(names) != len(counts):
        raise SystemExit(f"run_target_bench: {len(names)} regions named, {len(counts)} counted")
    # Each region less the harness's instructions in it (its cycles in the
    # same proportion: the profile counts instructions), then less the
    # markers' firmware-free remainder (the empty region "overhead").
    per_name, largest = {}, {}
    for index, (name, (i, c)) in enumerate(zip(names, counts)):
        h = 0 if name.startswith("calibration_") else harness.get(index, 0)  # the loop is the harness's
        own = (i - h, c * (i - h) / i if i else 0)
        total = per_name.get(name, (0, 0, 0))
        per_name[name] = (total[0] + own[0], total[1] + own[1], total[2] + 1)
        largest[name] = max(largest.get(name, own), own)
    oi, oc, _ = per_name.pop("overhead")
    regions = {name: (i - n * oi, c - n * oc) for name, (i, c, n) in per_name.items()}
    # A region measured more than once: its worst instance too.
    regions.update({f"{name}.worst": (i - oi, c - oc) for name, (i, c) in largest.items()
                    if per_name.get(name, (0, 0, 1))[2] > 1})
    extra = regions.pop("calibration_200")[0] - regions.pop("calibration_100")[0]
    if extra != KNOWN_LOOP:
        raise SystemExit(f"run_target_bench: 100 more iterations of a 2-instruction loop counted {extra} "
                         f"instructions on {cpu}, not {KNOWN_LOOP}: the plugin is not to be trusted")
    return regions, stats


sys.path.insert(0, str(ROOT / "protocol"))
import servo_schema  # noqa: E402  (the schema's reader, standard library only)


def unmeasured(measured: list) -> list:
    """Packets of the schema (protocol/servo_schema) that bench_protocol.c's every_packet
    leaves out, or measures without their answer: a new packet in the
    schema fails the run until it is measured. measured: [(code, "answer" |
    "quiet")] as the benchmark printed them."""
    seen = {}
    for code, kind in measured:
        seen.setdefault(int(code), set()).add(kind)
    missing = []
    for packet in servo_schema.load().packets:
        kinds = seen.get(packet.code, set())
        if not kinds:
            missing.append(f"{packet.name} (not measured)")
        elif packet.has("answers") and "answer" not in kinds:
            missing.append(f"{packet.name} (its answer not measured)")
    # A move's answer once it has finished (item 33): one packet's stands
    # for all (the same pass sends each).
    if not any("finished" in kinds for kinds in seen.values()):
        missing.append("the answer of a finished move (not measured)")
    return missing


def per_tick(motion: dict, region: str, nticks: int) -> tuple:
    """(instructions, cycles) of one tick of region."""
    return tuple(x / nticks for x in motion[region])


def after_a_missed_read(proto: dict, pass_: tuple) -> tuple:
    """A pass that sends, its byte landed just after the last pass read the
    ring: a main-loop round (awake_loop), then the pass but what comes
    before its reading of the ring (pass_to_ring)."""
    return tuple(r + p - b for r, p, b in zip(proto["awake_loop"], pass_, proto["pass_to_ring"]))


def figures(cpu: str, profile_region: str = "", by_line: bool = False) -> dict:
    """{figure: (instructions, cycles)}."""
    proto, pstats = run(CPUS[cpu] / "bench_protocol.elf", cpu, profile_region, by_line)
    missing = unmeasured(pstats["packets"])
    if missing:
        raise SystemExit(f"run_target_bench: bench_protocol.c on {cpu} leaves out packets of "
                         f"the schema: {', '.join(missing)}")
    motion, mstats = run(CPUS[cpu] / "bench_motion.elf", cpu, profile_region, by_line)
    nbytes, nticks = int(pstats["stream_bytes"]), int(mstats["ticks"])
    plans = {k: v for k, v in motion.items() if k.startswith("plan_") and not k.startswith("plan_jerk")}
    # Jerk-limited planning: the Cortex-M0 image leaves it out (its motion
    # library plans those moves as trapezoids): nan there.
    none = (float("nan"), float("nan"))
    jerk_plans = {k: none if cpu == "cortex-m0" else v for k, v in motion.items() if k.startswith("plan_jerk")}
    out = {
        "rx_per_byte": tuple(x / nbytes for x in proto["stream"]),
        "idle_poll": proto["idle_poll"],
        # One motion tick less the HAL double: the worse of a move the horn
        # follows and one it cannot; each also on its own.
        "tick": max(per_tick(motion, "ticks_follow", nticks),
                    per_tick(motion, "ticks_at_limit", nticks),
                    per_tick(motion, "ticks_stream", nticks)),
        "tick_follow": per_tick(motion, "ticks_follow", nticks),
        "tick_at_limit": per_tick(motion, "ticks_at_limit", nticks),
        # A 50 Hz stream's ticks (StreamSetpoint), the horn following.
        "tick_stream": per_tick(motion, "ticks_stream", nticks),
        # The whole control tick (servo_control_tick) on the followed move:
        # the mean of its ticks, as the motion tick's, and the worst one
        # (each tick is a region): a slow reading's turn, a profile segment.
        "servo_tick": per_tick(motion, "servo_tick", nticks),
        "servo_tick_worst": motion["servo_tick.worst"],
        # The pass after each of those ticks (safety_tend): the watchdog,
        # the winding's sample and model; outside the control tick.
        "safety_pass": per_tick(motion, "safety_pass", nticks),
        "safety_pass_worst": motion["safety_pass.worst"],
        "plan": max(plans.values()),
        **({"plan_jerk": max(jerk_plans.values())} if jerk_plans else {}),
    }
    # A Sync Monitor round of six servos (bench_protocol.c,
    # sync_monitor_round): each answer's way out after the byte that lets
    # it go (up to the UART's start), behind the main loop's round that may
    # have just missed that byte (awake_loop: a pass and servo_may_sleep,
    # the line in use; the worst). The first answer leaves in the pass that
    # frames the checksum byte wherever the record lies; listed first of
    # two (first_answer_of_two) that pass may frame the other record too.
    # On the M0 and M0+ the rest of that answer is built behind its first bytes
    # (sync_first_build, the longer of the two rounds').
    out.update({"awake_loop": proto["awake_loop"], "pass_to_ring": proto["pass_to_ring"],
                "first_answer": after_a_missed_read(proto, proto["sync_first_pass"]),
                "first_answer_of_two": after_a_missed_read(proto, proto["sync_first_pass_of_two"]),
                "sync_first_build": max(proto["sync_first_build"], proto["sync_first_build_of_two"]),
                "next_answer": after_a_missed_read(proto, proto["sync_next_pass"])})
    out.update({k: v for k, v in proto.items() if k.startswith(("answer_", "request_"))})
    out.update(plans)
    out.update(jerk_plans)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", type=Path, help="also write the figures here")
    ap.add_argument("--check", action="store_true",
                    help="fail when a figure is over its budget (those met so far)")
    ap.add_argument("--profile", metavar="REGION", default="",
                    help="print REGION's instructions by function (--cpu: the Cortex-M3 unless told)")
    ap.add_argument("--lines", action="store_true", help="with --profile: by source line instead")
    ap.add_argument("--cpu", default="cortex-m3", choices=sorted(CPUS), help="with --profile: which CPU's")
    ap.add_argument("--markdown", action="store_true", help="also print the table in Markdown (docs/benchmark.md)")
    ap.add_argument("--doc", type=Path, help="fail when this document's table (docs/benchmark.md) is not the one measured")
    args = ap.parse_args()
    if not PLUGIN.exists():
        sys.exit(f"run_target_bench: {PLUGIN} is missing: cmake --build --preset host")
    results = {cpu: figures(cpu, args.profile if cpu == args.cpu else "", args.lines) for cpu in CPUS}
    print(f"target benchmark: Thumb instructions executed, exact (QEMU 7.2 + plugin; the "
          f"calibration loop's {KNOWN_LOOP} counted exactly on each), and modelled cycles")
    heads = "".join(f" {SHORT[c] + ' instr':>10} {SHORT[c] + ' cycles':>11} {SHORT[c] + ' us':>7}" for c in CPUS)
    print(f"{'figure':<28}{heads}  budget {' | '.join(SHORT[c] for c in CPUS)}")
    over = []
    for key in results["cortex-m3"]:
        cells, marks = "", []
        for cpu in CPUS:
            i, c = results[cpu][key]
            mark, is_over = judge(cpu, key, i, c)
            over += [f"{key} ({SHORT[cpu]})"] * is_over
            marks.append(mark)
            cells += f" {i:>10.2f} {c:>11.1f} {c / CLOCK_MHZ[cpu]:>7.1f}"
        print(f"{key:<28}{cells}  {' | '.join(marks)}")
    table = markdown(results)
    if args.markdown:
        print("\n" + "\n".join(table))
    if args.json:
        args.json.write_text(json.dumps(results, indent=2))
    if over and args.check:
        sys.exit(f"run_target_bench: over budget: {', '.join(over)}")
    if args.doc:
        differ = doc_differs(args.doc, table)
        if differ:
            sys.exit(f"run_target_bench: {args.doc}'s table is not what the benchmark measures now "
                     f"(--markdown prints it):\n" + "\n".join(differ))
        print(f"run_target_bench: {args.doc}'s table is the benchmark's")


def markdown(results: dict) -> list:
    """The figures as docs/benchmark.md's table, a line each: the M3's
    instructions to two decimals, the others' to one."""
    names = [SHORT[c] for c in CPUS]
    lines = ["| figure | " + " | ".join(f"{n} instr | {n} cycles (µs)" for n in names) +
             f" | budget {' / '.join(names)} |",
             "|---|" + "---:|---:|" * len(CPUS) + "---|"]
    for key in results["cortex-m3"]:
        cells = []
        for cpu in CPUS:
            i, c = results[cpu][key]
            cells.append(f"{i:.2f}" if cpu == "cortex-m3" else f"{i:.1f}")
            cells.append(f"{c:.0f} ({c / CLOCK_MHZ[cpu]:.1f})")
        marks = [judge(cpu, key, *results[cpu][key])[0] or "–" for cpu in CPUS]
        budget = "" if all(m == "–" for m in marks) else " / ".join(marks)
        lines.append(f"| {key} | {' | '.join(cells)} | {budget} |")
    return lines


def doc_differs(doc: Path, table: list) -> list:
    """The lines where doc's table (the one that starts with the same
    header) and the measured one differ: '- doc' / '+ measured'."""
    lines = doc.read_text().splitlines()
    start = lines.index(table[0]) if table[0] in lines else len(lines)
    end = start
    while end < len(lines) and lines[end].startswith("|"):
        end += 1
    kept = lines[start:end]
    return [f"- {a}\n+ {b}" for a, b in zip(kept + [""] * len(table), table) if a != b] + \
        [f"- {a}" for a in kept[len(table):]]


if __name__ == "__main__":
    main()
