"""The answers of one servo's queries, decoded: Monitor, ReadMotion
(MotionSnapshot), ReadFaults (Fault) and ReadStore (StoreHealth)."""
from dataclasses import dataclass

from . import protocol as p


@dataclass
class Monitor:
    id: int
    voltage_mv: int
    current_ma: int
    power_mw: int
    temperature_adc: int
    status: int
    angle_decideg: int
    turns: int

    @classmethod
    def decode(cls, content: bytes) -> "Monitor":
        return cls(*p.decode_answer(p.MONITOR, content))


@dataclass
class MotionSnapshot:
    """ReadMotion (0x40): one instant of the motion state, docs/packets.md."""
    id: int
    angle_decideg: int
    setpoint_decideg: int
    target_decideg: int
    velocity_decideg_s: int
    tracking_error_centideg: int
    current_ma: int
    status: int
    flags: int
    time_us: int  # the servo's clock at the tick the values are from; wraps at 2**32
    winding_decic: int  # the winding's temperature, estimated (item 68)
    duty_q15: int  # the bridge's duty in damping and open loop (DriveDuty), after the limits; else 0

    PROFILE_ENDED, CLOCK_SLOWED, BRAKING, AT_LIMIT, RELEASED = 1, 2, 4, 8, 16
    # What holds the output back (flags bits 5-7, item 67; docs/safety.md);
    # "watchdog": a monitor released it, the bus watchdog or the oscillation
    # monitor (the newest fault says which).
    LIMITERS = ("none", "power", "current", "stall", "supply", "heat", "angle", "watchdog")

    @classmethod
    def decode(cls, content: bytes) -> "MotionSnapshot":
        return cls(*p.decode_answer(p.READ_MOTION, content))

    @property
    def limiter(self) -> str:
        return self.LIMITERS[self.flags >> 5]

    def seconds_since(self, earlier: "MotionSnapshot") -> float:
        """Servo time from an earlier snapshot to this one (less than 71
        minutes apart: the clock wraps)."""
        return ((self.time_us - earlier.time_us) % 2**32) / 1e6


@dataclass
class Fault:
    """ReadFaults (0x43): one fault of the history, kept across power
    cycles (docs/safety.md)."""
    id: int
    count: int         # faults in the history
    not_logged: int    # faults not written since power-up
    number: int
    op_seconds: int
    angle_decideg: int
    voltage_mv: int
    current_ma: int
    power_mw: int
    winding_decic: int
    case_decic: int
    what: int

    KINDS = {0: "none", 2: "stall", 3: "high_voltage", 4: "low_voltage", 5: "over_current",
             6: "over_power", 7: "over_temperature", 8: "watchdog", 9: "oscillation",
             10: "firmware_fault", 11: "watchdog_reset", 12: "software_reset", 13: "brown_out",
             14: "pin_reset", 15: "low_power_reset"}
    FIRMWARE_FAULT = 10  # the readings' bytes hold the code's frame (fault_code.py)

    @classmethod
    def decode(cls, content: bytes) -> "Fault":
        return cls(*p.decode_answer(p.READ_FAULTS, content))

    @property
    def kind(self) -> str:
        return self.KINDS.get(self.what, f"kind {self.what}")


@dataclass
class StoreHealth:
    """ReadStore (0x41): whether the user area is safely in flash, how worn
    the flash is, and what flash work cost the bus (docs/packets.md)."""
    id: int
    flags: int
    records: int
    page_erases: int
    rated_cycles: int
    budget: int
    op_seconds: int
    failures: int
    answers_dropped: int  # requests that arrived during an erase: carried out, not answered
    bytes_lost: int       # received bytes overwritten before the servo took them

    # The last change refused, and why.
    FLAGS = ("flash_refused", "over_wear_budget", "unstable", "needs_erase")
    # What the host can do about each (docs/decisions.md, "The config store").
    ADVICE = {
        "flash_refused": "its flash refused the write (a worn or failing page)",
        "over_wear_budget": "its flash wear budget allows no more saves yet (one per "
                            "so many seconds of operation; see 'servoctl store')",
        "unstable": "the drive items would make its loop unstable (docs/safety.md, \"Drive items the "
                    "loop refuses\")",
        "needs_erase": "its config page is full and the next is erased only while the servo "
                       "is released: release it ('servoctl stop ID'), leave the bus quiet for 0.1 s, "
                       "and write again",
    }

    @classmethod
    def decode(cls, content: bytes) -> "StoreHealth":
        return cls(*p.decode_answer(p.READ_STORE, content))

    def flag_names(self) -> list:
        return [name for bit, name in enumerate(self.FLAGS) if name and self.flags >> bit & 1]
