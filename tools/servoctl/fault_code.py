"""A firmware fault's record (ReadFaults' kind 10, docs/safety.md): the
readings' bytes hold the faulting code's frame instead (storage/fault_record.h,
struct fault_code), decoded here (fault_symbols.py names it from the image's ELF)."""
from dataclasses import dataclass

FIRMWARE_FAULT = 10  # Fault.what (answers.py): the readings' bytes hold the code's frame; above it, resets

EXCEPTIONS = {0: "stack guard (main loop)", 2: "NMI", 3: "HardFault", 4: "MemManage", 5: "BusFault",
              6: "UsageFault", 11: "SVCall", 14: "PendSV", 15: "SysTick"}
# CFSR bits 0-15 (ARMv7-M ARM B3.2.15-B3.2.16) and the record's usage byte.
MM_BUS_BITS = {0: "IACCVIOL", 1: "DACCVIOL", 3: "MUNSTKERR", 4: "MSTKERR", 7: "MMARVALID",
               8: "IBUSERR", 9: "PRECISERR", 10: "IMPRECISERR", 11: "UNSTKERR", 12: "STKERR", 15: "BFARVALID"}
USAGE_BITS = {0: "UNDEFINSTR", 1: "INVSTATE", 2: "INVPC", 3: "NOCP", 4: "UNALIGNED", 5: "DIVBYZERO",
              6: "VECTTBL", 7: "FORCED"}


@dataclass
class FaultCode:
    pc: int
    lr: int
    sp_offset: int      # the stack pointer less the RAM's base
    mm_bus_status: int
    exception: int
    usage_status: int

    @classmethod
    def of(cls, fault) -> "FaultCode":
        """From a Fault (answers.py) whose kind is firmware_fault."""
        return cls(pc=fault.angle_decideg & 0xFFFFFFFF, lr=fault.voltage_mv | fault.current_ma << 16,
                   sp_offset=fault.power_mw, mm_bus_status=fault.winding_decic & 0xFFFF,
                   exception=fault.case_decic & 0xFF, usage_status=(fault.case_decic >> 8) & 0xFF)

    @property
    def exception_name(self) -> str:
        e = self.exception
        return EXCEPTIONS.get(e, f"interrupt {e - 16}" if e >= 16 else f"exception {e}")

    @property
    def frame_valid(self) -> bool:
        """Whether pc and lr are the faulting code's: not when the stack
        overflowed (the M0's guard, exception 0; the core could not stack
        the frame, MSTKERR or STKERR)."""
        return self.exception != 0 and not self.mm_bus_status & (1 << 4 | 1 << 12)

    @property
    def status_bits(self) -> list:
        return ([name for bit, name in MM_BUS_BITS.items() if self.mm_bus_status >> bit & 1] +
                [name for bit, name in USAGE_BITS.items() if self.usage_status >> bit & 1])

    def describe(self, symbols=None) -> str:
        where = (f"pc {self.pc:#010x}{_in(symbols, self.pc)} lr {self.lr:#010x}{_in(symbols, self.lr)}"
                 if self.frame_valid else "pc unknown (the stack overflowed: no frame)")
        bits = " ".join(self.status_bits) or "-"
        return f"{self.exception_name}: {where} sp RAM+{self.sp_offset:#06x} [{bits}]"


def phrase(fault) -> str:
    """A Fault (answers.py) as a phrase: its readings, or for the servo's
    own (kinds 10-15, no readings) a firmware fault's exception and PC, a
    reset's kind alone."""
    f = fault
    if f.what == FIRMWARE_FAULT:
        code = FaultCode.of(f)
        where = f"pc {code.pc:#010x}" if code.frame_valid else "no frame"
        return f"#{f.number} {f.kind} ({code.exception_name}, {where})"
    if f.what > FIRMWARE_FAULT:
        return f"#{f.number} {f.kind}"
    return (f"#{f.number} {f.kind} at {f.angle_decideg / 10:.1f} deg, {f.voltage_mv / 1000:.2f} V, "
            f"{f.winding_decic / 10:.0f} C winding")


def _in(symbols, address: int) -> str:
    name = symbols.name(address) if symbols else None
    return f" ({name})" if name else ""
