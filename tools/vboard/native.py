"""The host build's models through ctypes (native/vboard_native.c): the
simulator's motor and winding, the config store's factory record, and the
wire's rule where two drivers overlap."""
import ctypes
import os
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DEFAULT = REPO / "build/host/tools/vboard/native/libvboard_native.so"
QUANTITIES = {"angle_deg": 0, "velocity_dps": 1, "current_a": 2, "supply_v": 3, "load_nm": 4,
              "winding_c": 5, "case_c": 6, "ambient_c": 7, "stop_deg": 8, "soak_c": 9, "payload_gcm2": 10}


def _library():
    path = Path(os.environ.get("VBOARD_NATIVE", DEFAULT))
    if not path.exists():
        raise FileNotFoundError(f"no {path}: build it with 'cmake --preset host && cmake --build --preset host'")
    lib = ctypes.CDLL(str(path))
    lib.vboard_motor_size.restype = ctypes.c_uint32
    lib.vboard_motor_init.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double]
    lib.vboard_motor_load_plant.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_double, ctypes.c_char_p,
                                            ctypes.c_uint32]
    lib.vboard_motor_step.argtypes = [ctypes.c_void_p, ctypes.c_double]
    lib.vboard_motor_drive.argtypes = [ctypes.c_void_p, ctypes.c_double]
    lib.vboard_motor_coast.argtypes = [ctypes.c_void_p]
    lib.vboard_motor_encoder.argtypes = [ctypes.c_void_p]
    lib.vboard_motor_encoder.restype = ctypes.c_uint16
    lib.vboard_motor_get.argtypes = [ctypes.c_void_p, ctypes.c_int]
    lib.vboard_motor_get.restype = ctypes.c_double
    lib.vboard_motor_set.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double]
    lib.vboard_motor_ntc_adc.argtypes = [ctypes.c_void_p]
    lib.vboard_motor_ntc_adc.restype = ctypes.c_uint
    lib.vboard_factory_config.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.c_uint32, ctypes.c_uint8]
    lib.vboard_stored_id.argtypes = [ctypes.c_char_p, ctypes.c_uint32, ctypes.c_uint32]
    lib.wire_overlap.argtypes = [ctypes.c_uint8, ctypes.c_uint8, ctypes.c_int64, ctypes.c_int64]
    lib.wire_overlap.restype = ctypes.c_uint8
    return lib


_lib = None


def lib():
    global _lib
    if _lib is None:
        _lib = _library()
    return _lib


class Motor:
    """plant.c and thermal.c: the motor, gears, horn and winding; the reference
    servo's, or a plant file's (hal/ports/host/plants). supply_v None: the plant's."""

    def __init__(self, supply_v: float | None, ambient_c: float, plant: str | None = None):
        self.buf = ctypes.create_string_buffer(lib().vboard_motor_size())
        lib().vboard_motor_init(self.buf, 7.4 if supply_v is None else supply_v, ambient_c)
        if plant is not None:
            err = ctypes.create_string_buffer(256)
            if not lib().vboard_motor_load_plant(self.buf, str(plant).encode(), ambient_c, err, len(err)):
                raise ValueError(err.value.decode())
            if supply_v is not None:
                self.set("supply_v", supply_v)

    def step(self, dt: float) -> None:
        if dt > 0:
            lib().vboard_motor_step(self.buf, dt)

    def drive(self, duty: float) -> None:
        lib().vboard_motor_drive(self.buf, duty)

    def coast(self) -> None:
        lib().vboard_motor_coast(self.buf)

    def encoder(self) -> int:
        return lib().vboard_motor_encoder(self.buf)

    def ntc_adc(self) -> int:
        return lib().vboard_motor_ntc_adc(self.buf)

    def get(self, what: str) -> float:
        return lib().vboard_motor_get(self.buf, QUANTITIES[what])

    def set(self, what: str, value: float) -> None:
        lib().vboard_motor_set(self.buf, QUANTITIES[what], value)


def factory_config(pages, page_size: int, page0: int, servo_id: int) -> bool:
    return bool(lib().vboard_factory_config(pages, page_size, page0, servo_id))


def wire_overlap(heard: int, other: int, lag_s: float, byte_s: float) -> int:
    """servo_sim's rule where two drivers overlap (hal/ports/host/wire_overlap.h):
    the byte a receiver framed on `heard` gets when `other` started lag_s after it."""
    return lib().wire_overlap(heard, other, round(lag_s * 1e9), round(byte_s * 1e9))


def stored_id(pages: bytes, page_size: int, page0: int) -> int:
    """The servo ID the config pages hold (the firmware's config_peek)."""
    return lib().vboard_stored_id(pages, page_size, page0)
