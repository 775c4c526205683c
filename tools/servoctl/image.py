"""Application images for the bootloader, as servoctl makes and checks
them: servo_image (bootloader/servo_image, which the firmware's
build runs too), its errors servoctl's UsageError."""
import functools

import servo_image
from servo_image import (BOARD_MARK_OFFSET, BOARD_MARK_TAG, BOARDS, CHECKED, FORMAT,  # noqa: F401
                         HEADER_SIZE, MAGIC, Board, Image, board_named, boards)

from .errors import UsageError


def _usage(function):
    @functools.wraps(function)
    def call(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except servo_image.ImageError as e:
            raise UsageError(str(e)) from e.__cause__
    return call


check_code, build, parse, load, make = (_usage(f) for f in (
    servo_image.check_code, servo_image.build, servo_image.parse, servo_image.load, servo_image.make))
