#!/usr/bin/env python3
"""Worst-case stack use of an image, from GCC's call graphs
(-fcallgraph-info=su, one .ci file per object) and the linked symbols.

Roots: main and every interrupt handler defined in the image. Functions
nothing calls directly are what a function only reached through a pointer
looks like; the firmware has three kinds of function pointer, and an
indirect call is bounded by the worst target of its kind:
  in dispatch(_packet) the packet handlers (handle_*)
  in usart_hd_irq      the clock that stamps received bytes (systick_now_us)
  in a packet handler  the application's hooks (servo_persist_config, the fault
                       history's fault_log_read and clear_faults), or a HAL op
  anywhere else        the port's HAL operations (everything else)
Recursion is an error. A library function without a call graph (memcpy, libgcc) is charged
LIBRARY_BYTES. All interrupts share one priority, so they do not nest: the
worst case is main's deepest path plus the deepest handler plus the
Cortex-M3's 32-byte exception frame. The NMI (the G0's flash ECC error)
preempts any handler: where the image has one, its depth and a second frame
come on top. A naked handler's calls are in assembly, which the call graphs
do not show: ASM_CALLS gives its pushes and callees. Fails when that
exceeds the stack the linker script reserves, less a margin."""
import argparse
import pathlib
import re
import subprocess
import sys

LIBRARY_BYTES = 64
# {naked handler: (bytes its assembly pushes, functions it calls)}
ASM_CALLS = {"NMI_Handler": (8, ("flash_g0_nmi_ecc",))}  # startup_stm32g031.c: push {r0, lr}
EXCEPTION_FRAME = 32
MARGIN = 0.25

node_re = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"')
edge_re = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')


def load(ci_files, linked):
    stack, calls, qualifier = {}, {}, {}
    for path in ci_files:
        for line in path.read_text().splitlines():
            m = node_re.search(line)
            if m:
                title, label = m.groups()
                b = re.search(r"\\n(\d+) bytes \((\w+)\)", label)
                if b:
                    stack[title] = int(b.group(1))
                    qualifier[title] = b.group(2)
                continue
            m = edge_re.search(line)
            if m:
                calls.setdefault(m.group(1), set()).add(m.group(2))
    # Keep only what the image links (static functions are "file:name").
    keep = {t for t in stack if t.split(":")[-1] in linked}
    return ({t: stack[t] for t in keep}, {t: calls.get(t, set()) for t in keep},
            {t: qualifier[t] for t in keep})


def image_call_graphs(elf, build_dir):
    """The .ci files of the objects the image links, from its linker map
    (NAME.map beside NAME.elf): the objects given to the link and the
    archive members it took. A build holds the other board family's port
    too, whose functions have the same names (USART1_IRQHandler); only the
    image's own may count. Archive lib<target>.a's members are built in
    CMakeFiles/<target>.dir below the archive's folder."""
    text = pathlib.Path(elf).with_suffix(".map").read_text()
    build = pathlib.Path(build_dir)
    files = set()
    for obj in re.findall(r"^LOAD (\S+\.obj)$", text, re.M):
        files.add(build / obj)
    for folder, target, member in set(re.findall(r"^(\S+)/lib([^/\s]+)\.a\((\S+\.obj)\)$", text, re.M)):
        found = list((build / folder / "CMakeFiles" / f"{target}.dir").rglob(member))
        if not found:
            raise SystemExit(f"stack-report: no object {member} of lib{target}.a under {folder}")
        files.update(found)
    # What the link-time optimisation compiled (the application's jobs and
    # main loop, servo_app): its partitions' own .ci files, named after the
    # image (the link's -fcallgraph-info; older ones are removed before it).
    partitions = sorted(pathlib.Path(elf).parent.glob(pathlib.Path(elf).name + ".ltrans*.ci"))
    # An object compiled for the link-time optimisation holds no code yet:
    # its own .ci describes nothing that runs (the partitions' do).
    compiled = [f for f in files if f.with_suffix(".ci").exists() and b".gnu.lto_" not in f.read_bytes()]
    return [f.with_suffix(".ci") for f in compiled] + partitions


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("elf")
    ap.add_argument("build_dir")
    ap.add_argument("--nm", default="arm-none-eabi-nm")
    ap.add_argument("--size", default="arm-none-eabi-size")
    args = ap.parse_args()
    # The stack the linker script reserves: the .stack section.
    sections = subprocess.run([args.size, "-A", args.elf], capture_output=True, text=True,
                              check=True).stdout
    stack_line = [l.split() for l in sections.splitlines() if l.startswith(".stack ")]
    if not stack_line:
        print("error: the image has no .stack section", file=sys.stderr)
        return 1
    args.stack_size = int(stack_line[0][1])
    nm = subprocess.run([args.nm, args.elf], capture_output=True, text=True, check=True).stdout
    linked = {line.split()[-1] for line in nm.splitlines() if re.match(r"\S+ [tT] ", line)}
    ci_files = image_call_graphs(args.elf, args.build_dir)
    stack, calls, qualifier = load(ci_files, linked)
    for t in [t for t in stack if t.split(":")[-1] in ASM_CALLS]:
        pushed, callees = ASM_CALLS[t.split(":")[-1]]
        stack[t] = max(stack[t], pushed)
        calls[t] = calls[t] | {c for c in stack if c.split(":")[-1] in callees}
    # A function the image links whose frame no call graph gives would
    # count as nothing: the main loop's is the one that matters.
    if "servo_poll" in linked and not any(t.split(":")[-1] == "servo_poll" for t in stack):
        print("error: the image links servo_poll but no call graph describes it (an object "
              "compiled for the link-time optimisation, and no partition's .ci?)", file=sys.stderr)
        return 1
    dynamic = [t for t, q in qualifier.items() if q != "static"]
    roots = [t for t in stack if t.split(":")[-1] == "main" or (
        t.split(":")[-1].endswith("Handler") and t.split(":")[-1] != "Reset_Handler")]
    called = {c for cs in calls.values() for c in cs}
    # Vector-table entries are reached by the hardware, not our pointers.
    pointer_targets = [t for t in stack if t not in called and t not in roots
                       and not t.split(":")[-1].endswith("Handler")]

    def short(t):
        return t.split(":")[-1]

    handlers = [t for t in pointer_targets if short(t).startswith("handle_")]
    kinds = {
        # dispatch_packet is dispatch's, inlined or not.
        "dispatch": handlers,
        "dispatch_packet": handlers,
        # systick_now_us is also called directly, so it is no pointer target.
        "usart_hd_irq": [t for t in stack if short(t) == "systick_now_us"],
    }
    app_hooks = ("persist_config", "fault_log_read", "clear_faults")
    persist = [t for t in pointer_targets if short(t) in app_hooks]
    hal_ops = [t for t in pointer_targets
               if not short(t).startswith("handle_") and short(t) not in app_hooks]
    memo = {}
    indirect_below = {}

    class Recursion(Exception):
        pass

    def has_indirect(title, seen=frozenset()):
        if title not in stack or title in seen:
            return False
        if title not in indirect_below:
            cs = calls[title]
            indirect_below[title] = "__indirect_call" in cs or any(
                has_indirect(c, seen | {title}) for c in cs)
        return indirect_below[title]

    def worst(title, path):
        if title in path:
            raise Recursion(title)
        if title not in stack:
            return LIBRARY_BYTES, [title.split(":")[-1] + " (library)"]
        if title in memo:
            return memo[title]
        best, chain = 0, []
        for callee in calls[title]:
            if callee == "__indirect_call":
                targets = kinds.get(short(title), hal_ops)
                if short(title).startswith(("handle_", "commit_user")):
                    targets = hal_ops + persist  # the writes, ReadFaults, ClearFaults
                for c in targets:
                    d, ch = worst(c, path + (title,))
                    if d > best:
                        best, chain = d, ["(indirect) " + ch[0]] + ch[1:]
            else:
                d, ch = worst(callee, path + (title,))
                if d > best:
                    best, chain = d, ch
        result = (stack[title] + best, [title.split(":")[-1]] + chain)
        if not has_indirect(title):
            memo[title] = result  # path-independent
        return result

    try:
        results = {r.split(":")[-1]: worst(r, ()) for r in roots}
    except Recursion as e:
        print(f"error: recursion through {e}: no static stack bound", file=sys.stderr)
        return 1
    main_depth = results.get("main", (0, []))[0]
    handlers = {k: v for k, v in results.items() if k not in ("main", "NMI_Handler")}
    worst_handler = max(handlers.items(), key=lambda kv: kv[1][0]) if handlers else ("none", (0, []))
    nmi = results["NMI_Handler"][0] + EXCEPTION_FRAME if "NMI_Handler" in results else 0
    total = main_depth + EXCEPTION_FRAME + worst_handler[1][0] + nmi
    limit = int(args.stack_size * (1 - MARGIN))
    print(f"stack: {pathlib.Path(args.elf).name}: worst case {total} B of {args.stack_size} B reserved "
          f"(main {main_depth} + exception frame {EXCEPTION_FRAME} + {worst_handler[0]} "
          f"{worst_handler[1][0]}{f' + NMI with its frame {nmi}' if nmi else ''}); limit with {int(MARGIN * 100)}% margin {limit} B")
    for name, (depth, chain) in sorted(results.items()):
        print(f"  {name:<20} {depth:5d} B  {' > '.join(chain[:9])}{' > ...' if len(chain) > 9 else ''}")
    if dynamic:
        print(f"error: functions with dynamic stack use: {', '.join(dynamic)}", file=sys.stderr)
        return 1
    if total > limit:
        print(f"error: worst-case stack {total} B exceeds {limit} B", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
