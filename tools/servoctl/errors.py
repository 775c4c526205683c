"""Every error servoctl reports, each with the exit code of the command line
(docs/servoctl.md, the exit codes). The lowest module: every other may raise these."""

EXIT_INTERRUPTED = 130  # the command line's exit code after Ctrl-C


class ServoError(Exception):
    """Base of every error servoctl reports. exit_code is the command
    line's (docs/servoctl.md, the exit codes)."""
    exit_code = 1


class Refused(ServoError):
    """The servo answered but did not do it (result 0, status bit 1, a
    protection), or a move did not arrive."""
    exit_code = 1


class UsageError(ServoError):
    """A value, name, file or option the tool cannot use: nothing was sent."""
    exit_code = 2


class ValueOutOfRange(UsageError):
    pass


class NotSent(UsageError, Refused):
    """servoctl refused a value before sending it, one the servo's state or
    kind makes wrong: a target in another turn, an ID another servo
    answers at, an image for another board or larger than its slot.
    Nothing was changed: the exit code of every value refused before
    sending (2), and a Refused for the Python API."""


class NoReply(ServoError):
    """No servo answered (absent, another ID, another baud rate)."""
    exit_code = 3


class BadChecksum(NoReply):
    pass


class BadAnswer(NoReply):
    """An answer came with a good checksum but not the length its packet
    has: garbled on the wire, another firmware, or two servos on one ID.
    No usable reply, so the same exit code as none."""


class LinkError(ServoError):
    """The serial port or socket failed: cannot open, gone, write error."""
    exit_code = 4


class NotPutBack(ServoError):
    """A command that stopped part-way could not put back a stored item it
    had written along the way (putback.py): the servo holds a value no one
    chose (a binary search's midpoint). Its own exit code, so a script
    cannot take it for a plain interruption or refusal."""
    exit_code = 5
