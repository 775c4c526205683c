#!/usr/bin/env python3
"""Checks the ports' register definitions against ST's register descriptions.

    python3 scripts/check_regs_svd.py [--header-dir DIR] [--svd-dir DIR]

Every macro that hal/ports/stm32f1/stm32f1_regs.h, stm32f0/stm32f0_regs.h
and stm32_common/stm32_core_regs.h define is evaluated by the host C compiler
(with the part's header, so the shared header is checked against both parts)
and judged against the part's SVD file as cmsis-svd 0.4 bundles it
(STMicro/STM32F103xx.svd, STMicro/STM32F030.svd), and stm32g0/stm32g0_regs.h
against ST's STM32G031.svd where it is given (--svd-dir; no package ships it):

- a register (REG32, *_ADDR, *_OFFSET from its peripheral's *_BASE) must be
  the register of that name at that address;
- a peripheral base must be that peripheral's base address;
- a bit or field value (NAME = REGISTER_FIELD[_VALUE]) must set only the
  bits of that field, and a one-bit field exactly its bit;
- a value that sets several fields is listed in COMPOSITES with the field
  values it means, and must equal them placed where the SVD puts them;
- an interrupt number must be the SVD's number for the interrupt named in
  IRQS; a *_SHIFT, where its field starts.

A macro that fits none of these is named in NOT_IN_SVD with where its value
comes from instead, or the check fails: a new definition is checked too.
Exit 1 with one line per mismatch."""
import argparse
import atexit
import lzma
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
PORTS = ROOT / "hal/ports"
PARTS = {
    "STM32F103xx": "stm32f1/stm32f1_regs.h",
    "STM32F030": "stm32f0/stm32f0_regs.h",
    "STM32G031": "stm32g0/stm32g0_regs.h",
}
# What a part's header is compiled with.
DEFINES = {"STM32G031": ["-DSTM32_FAMILY_G0"]}
# SVD files no package on PyPI ships (cmsis-svd 0.4's stop before the G0;
# 0.5 and 0.6 ship none, pyOCD's have no G0): NAME.svd in the folder given
# (--svd-dir, or $SERVO_SVD_DIR), else the project's copy (KEPT_SVD).
SVD_GIVEN = {"STM32G031"}


# The project keeps ST's own file, compressed (its Apache-2.0 header kept):
# hal/ports/<family>/svd/NAME.svd.xz.
KEPT_SVD = Path(__file__).resolve().parent.parent / "hal" / "ports"


def svd_file(svd_name: str, svd_dir=None):
    """The part's SVD file where it is not packaged: a Path (the folder
    given, else the project's copy, unpacked to a temporary file), or None."""
    folder = svd_dir or os.environ.get("SERVO_SVD_DIR")
    path = Path(folder) / f"{svd_name}.svd" if folder else None
    if path and path.is_file():
        return path
    kept = sorted(KEPT_SVD.glob(f"*/svd/{svd_name}.svd.xz"))
    if not folder and kept:
        folder = tempfile.mkdtemp(prefix="svd-")
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        out = Path(folder) / f"{svd_name}.svd"
        out.write_bytes(lzma.decompress(kept[0].read_bytes()))
        return out
    return None
CORE = "stm32_common/stm32_core_regs.h"

from svd_names import (CALLS, COMPOSITES, FIELD_NAMES, IRQS, NOT_IN_SVD, PART_CALLS,  # noqa: E402
                       PART_COMPOSITES, PART_NOT_IN_SVD, REGISTER_NAMES)


def defined_macros(header: Path) -> list:
    """[(name, is_function_like)] in the order the header defines them."""
    out = []
    for line in header.read_text().splitlines():
        m = re.match(r"#define\s+([A-Z0-9_]+)(\()?", line)
        if m and not m.group(1).endswith("_H"):
            out.append((m.group(1), bool(m.group(2))))
    return out


def expression(name: str, function_like: bool, calls=CALLS) -> str:
    if not function_like:
        return name
    arg = next((a for prefix, a in calls.items() if name.startswith(prefix)), None)
    return f"{name}({arg})" if arg else ""


def evaluate(header_dir: Path, part_header: str, names: list, defines=(), calls=CALLS) -> dict:
    """{name: (value, is_register)}: REG32(a) becomes a marked a."""
    lines = [f'#include "ports/{part_header}"', "#include <stdio.h>", "#undef REG32",
             "#define REG32(a) (0x100000000ull | (unsigned long long)(a))", "int main(void) {"]
    for name, fn in names:
        expr = expression(name, fn, calls)
        if expr and name != "REG32":  # what this part's build leaves out, left out
            lines += [f"#ifdef {name}", f'printf("%s %llu\\n", "{name}", (unsigned long long)({expr}));',
                      "#endif"]
    lines.append("return 0; }")
    with tempfile.TemporaryDirectory() as tmp:
        src, exe = Path(tmp) / "eval.c", Path(tmp) / "eval"
        src.write_text("\n".join(lines) + "\n")
        dirs = [f"-I{header_dir.parent}"]  # the headers name each other as ports/...
        subprocess.run(["cc", "-w", *defines, *dirs, str(src), "-o", str(exe)], check=True)
        out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    values = {}
    for line in out.splitlines():
        name, value = line.split()
        v = int(value)
        values[name] = (v & 0xFFFFFFFF, bool(v >> 32))
    return values


class Part:
    def __init__(self, svd_name: str, svd_file=None):
        from cmsis_svd.parser import SVDParser
        self.name = svd_name
        parser = (SVDParser.for_xml_file(str(svd_file)) if svd_file
                  else SVDParser.for_packaged_svd("STMicro", svd_name + ".svd"))
        self.device = parser.get_device()
        self.by_address = {}
        self.bases = {}
        self.interrupts = {}
        for p in self.device.peripherals:
            self.bases[p.base_address] = p.name
            for r in p.registers:
                self.by_address.setdefault(p.base_address + r.address_offset, []).append((p.name, r))
            for i in p.interrupts or []:
                self.interrupts[i.name] = i.value


def plain(name: str) -> str:
    """The name without its family's prefix: G0_RCC_BASE -> RCC_BASE."""
    return re.sub(r"^G0_", "", name)


def register_token(name: str) -> str:
    """USART_SR -> SR, DMA1_CCR5_ADDR -> CCR5, USART_RDR_OFFSET -> RDR."""
    stem = re.sub(r"_(ADDR|OFFSET)$", "", name)
    return stem.split("_")[-1]


def register_matches(token: str, svd_name: str) -> bool:
    # The SVD numbers a register the header takes by argument (CCR1, ISER0)
    # and names a timer's CCMR by its mode (CCMR1_Output).
    return svd_name in (token, token + "0", token + "_Output") or re.fullmatch(token + r"\d", svd_name)


def check_part(svd_name: str, header_dir: Path, svd_file=None) -> list:
    part = Part(svd_name, svd_file)
    part_header = PARTS[svd_name]
    names = defined_macros(header_dir / CORE) + defined_macros(header_dir / part_header)
    values = evaluate(header_dir, part_header, names, DEFINES.get(svd_name, ()), {**CALLS, **PART_CALLS.get(svd_name, {})})
    errors = []
    registers = {}  # register macro -> (peripheral, svd register)
    not_in_svd = {**NOT_IN_SVD, **PART_NOT_IN_SVD.get(svd_name, {})}
    composites = {**COMPOSITES, **PART_COMPOSITES.get(svd_name, {})}

    def fail(name, why):
        errors.append(f"{svd_name}: {name}: {why}")

    # Registers first: the fields are looked up through them.
    for name, fn in names:
        if name not in values:
            continue
        value, is_reg = values[name]
        if name.endswith("_OFFSET"):
            base = next((values[b][0] for b, _ in names if b.endswith("_BASE") and plain(name).split("_")[0] in b), None)
            value, is_reg = (base or 0) + value, True
        if not (is_reg or name.endswith("_ADDR")) or name in not_in_svd:
            continue
        found = part.by_address.get(value, [])
        token = REGISTER_NAMES.get(name, register_token(name))
        match = [(p, r) for p, r in found if register_matches(token, r.name)]
        if not match:
            have = ", ".join(f"{p}.{r.name}" for p, r in found) or "no register"
            fail(name, f"{value:#010x} is {have} in the SVD, not {register_token(name)}")
            continue
        registers[name] = match[0]

    for name, fn in names:
        if name in not_in_svd or name in registers:
            continue
        if name not in values:
            if fn and name not in composites:
                fail(name, "a function-like macro with no argument in CALLS")
            continue
        value, is_reg = values[name]
        if is_reg or name.endswith(("_ADDR", "_OFFSET")):
            continue  # a register that failed above
        if name.endswith("_BASE") or plain(name) == "FLASH_BASE_REG":
            periph = part.bases.get(value)
            want = plain(name).replace("_BASE_REG", "").replace("_BASE", "")
            if periph is None or periph.upper().rstrip("1") != want.upper().rstrip("1"):
                fail(name, f"{value:#010x} is the base of {periph or 'nothing'} in the SVD, not {want}")
            continue
        if name in IRQS:
            irq = IRQS[name].get(svd_name)
            if irq is None:
                fail(name, "no interrupt named for this part in IRQS")
            elif part.interrupts.get(irq) != value:
                fail(name, f"{value} is not {irq}'s interrupt number ({part.interrupts.get(irq)})")
            continue
        if name in composites:
            reg_macro, fields = composites[name]
            if reg_macro not in registers:
                if reg_macro in values or any(n == reg_macro for n, _ in names):
                    fail(name, f"its register {reg_macro} is not in the SVD")
                continue  # a register the other part's header defines
            _, reg = registers[reg_macro]
            by_name = {f.name: f for f in reg.fields}
            want = 0
            for field, v in fields.items():
                f = by_name.get(field)
                if f is None:
                    fail(name, f"{reg.name} has no field {field} in the SVD")
                    break
                want |= v << f.bit_offset
            else:
                if want != value:
                    fail(name, f"{value:#x} is not {fields} in {reg.name} ({want:#x})")
            continue
        check_field(part, name, value, registers, names, fail)
    return errors


def check_field(part, name, value, registers, names, fail):
    """NAME = REGISTER_FIELD[_VALUE]: only the field's bits."""
    prefix = max((r for r in registers if name.startswith(r + "_")), key=len, default=None)
    if prefix is None:
        # A register only the other part defines keeps its fields out.
        if not any(name.startswith(n + "_") for n, _ in names):
            fail(name, "no register of this header starts its name: add it to COMPOSITES or NOT_IN_SVD")
        return
    _, reg = registers[prefix]
    rest = name[len(prefix) + 1:].split("_")
    key = (part.name, name) if (part.name, name) in FIELD_NAMES else (None, name)
    if key in FIELD_NAMES and FIELD_NAMES[key] is None:
        return
    if rest[-1] == "SHIFT":
        rest = rest[:-1]
    candidates = [FIELD_NAMES[key]] if key in FIELD_NAMES else ["_".join(rest[:i]) for i in range(len(rest), 0, -1)]
    field = next((f for c in candidates for f in reg.fields if f.name == c), None)
    if field is None:
        fail(name, f"{reg.name} has no field {candidates[-1]} in the SVD")
        return
    if name.endswith("_SHIFT"):  # where the field starts
        if value != field.bit_offset:
            fail(name, f"{value} is not where {reg.name}.{field.name} starts (bit {field.bit_offset})")
        return
    mask = ((1 << field.bit_width) - 1) << field.bit_offset
    if value & ~mask or value == 0 and field.bit_width == 1:
        fail(name, f"{value:#x} lies outside {reg.name}.{field.name} (bits {field.bit_offset}.."
                   f"{field.bit_offset + field.bit_width - 1})")
    elif field.bit_width == 1 and value != mask:
        fail(name, f"{value:#x} is not {reg.name}.{field.name} ({mask:#x})")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--header-dir", type=Path, default=PORTS, help="the ports' folder, named ports (its headers include each other as ports/...; tests use a copy)")
    ap.add_argument("--svd-dir", type=Path, help=f"a folder with {', '.join(sorted(SVD_GIVEN))}.svd (default $SERVO_SVD_DIR)")
    args = ap.parse_args()
    errors, checked = [], 0
    for svd_name, header in PARTS.items():
        given = svd_file(svd_name, args.svd_dir) if svd_name in SVD_GIVEN else None
        if svd_name in SVD_GIVEN and given is None:
            print(f"{svd_name}: not checked: no {svd_name}.svd (--svd-dir or $SERVO_SVD_DIR)")
            continue
        errors += check_part(svd_name, args.header_dir, given)
        checked += len(defined_macros(args.header_dir / CORE) + defined_macros(args.header_dir / header))
    for e in errors:
        print(e)
    print(f"registers: {checked} definitions against ST's SVD files, {len(errors)} mismatches")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
