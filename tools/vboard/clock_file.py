"""The bus clock where a host reads it without asking, as servo_sim's
(firmware/boards/host_sim/sim_clock.h, docs/simulator.md): a 16-byte file
in the state folder, mapped. At offset 0 the boards' clock in microseconds
(little-endian u64, one store after every slice); at offset 8 the host may
write the bus time it waits for: until the clock reaches it the boards run
as fast as the emulator can, then follow the wall clock again from there.
With UNTIL_ANSWER (bit 63) set the host waits for an answer: the running
ahead stops once the host has been handed bytes since its last and the
wire and the adapter hold none. 0, the file's start, never runs ahead: a
host that does not write it (a person, servoctl sim) meets real time.
Boards run with --clock paced never follow the wall clock: they stand
still once they reach the host's wait (or answer it), and run only once
they have read every byte the host says it has sent (offset 16); at
offset 24 the host says how many it has read, and one that waits for an
answer having read all it was handed waits for more (servo_sim's rules)."""
import mmap
import os
import struct

CLOCK_FILE = "bus.clock"  # servo_sim's name (SIM_CLOCK_FILE)
UNTIL_ANSWER = 1 << 63
_U64 = struct.Struct("<Q")  # the native store on a little-endian host: one 8-byte move


class ClockFile:
    def __init__(self, state_dir: str):
        self.path = os.path.join(state_dir, CLOCK_FILE)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o644)
        try:
            os.ftruncate(fd, 4 * _U64.size)
            self._map = mmap.mmap(fd, 4 * _U64.size)
        finally:
            os.close(fd)  # the mapping keeps the file

    def publish(self, now_s: float) -> None:
        # Rounded: the boards' seconds are sums of slices, and 2.01 s is
        # 2009999.9999... us; truncated, a host waiting for 2.01 s would
        # never see it reached where paced boards stand still at it.
        _U64.pack_into(self._map, 0, round(now_s * 1e6))

    def host_waits(self):
        """(the bus time the host waits for, s; whether for an answer)."""
        while True:  # twice alike: a copy that overlapped the host's store is read again
            word = _U64.unpack_from(self._map, 8)[0]
            if _U64.unpack_from(self._map, 8)[0] == word:
                return (word & ~UNTIL_ANSWER) / 1e6, bool(word & UNTIL_ANSWER)

    def host_sent(self) -> int:
        """The bytes a paced host says it has sent on the bus in all."""
        return _U64.unpack_from(self._map, 16)[0]

    def host_received(self) -> int:
        """The bytes a paced host says it has read off the bus in all."""
        return _U64.unpack_from(self._map, 24)[0]

    def close(self) -> None:
        self._map.close()
        try:
            os.unlink(self.path)
        except OSError:
            pass
