"""Several servos on one simulated bus: unsolicited answers (a finished move
with control response on) take turns with each other and with answers the
host asked for. The simulator counts a servo that starts while another's
bytes are on the wire as a collision; the fixture fails on any."""
import struct

from servoctl import protocol as p
from servoctl.protocol import checksum, request_frame
from servoctl.servo import Servo


def frames_in(data: bytes):
    """(code, content, checksum ok) of every response frame in data, and how
    many bytes were not part of one."""
    frames, stray, i = [], 0, 0
    while i < len(data):
        if data[i:i + 2] != p.RESPONSE_HEADER or i + 5 > len(data):
            stray += 1
            i += 1
            continue
        end = i + 4 + data[i + 3] + 1
        frame = data[i:end]
        frames.append((frame[2], frame[4:-1], len(frame) == end - i and checksum(frame[:-1]) == frame[-1]))
        i = end
    return frames, stray


def test_finished_moves_answer_in_turn_with_other_traffic(sim3):
    """Servos 1 and 2 finish moves about a millisecond apart while the host
    keeps servo 3 busy answering pings; then the host listens. Every answer
    arrives whole: the finished answers in their slots once the line is
    quiet (docs/decisions.md, "Sharing the bus"). Time is the simulator's:
    the pings go on for 0.4 s of it, and at least 50 of them."""
    with sim3.bus() as bus:
        for i in (1, 2):
            Servo(bus, i).write("soft_start_on", 0)
            Servo(bus, i).write("control_response", 1)
        for trial in range(10):
            angle = 300 if trial % 2 == 0 else -300
            bus.serial.reset_input_buffer()
            for i in (1, 2):
                bus.serial.write(request_frame(p.ANGLE, struct.pack("<BhHH", i, angle, 150, 0)))
            data = b""
            pinged = 0
            until = sim3.clock_s() + 0.4
            while pinged < 50 or sim3.clock_s() < until:
                bus.serial.write(request_frame(p.PING, bytes([3])))
                pinged += 1
                # 2 ms of the simulator's time between pings: on a loaded PC
                # 2 ms of the host's let pings bunch up on the wire, each
                # cutting the answer to the one before short.
                sim3.sleep(0.002)
                data += bus.serial.read(4096)
            sim3.sleep(0.4)
            data += bus.serial.read(4096)
            frames, stray = frames_in(data)
            assert stray == 0, f"trial {trial}: {stray} bytes outside any frame"
            assert all(ok for _, _, ok in frames), f"trial {trial}: a garbled frame"
            finished = sorted(c[0] for code, c, _ in frames if code == p.ANGLE)
            assert finished == [1, 2], f"trial {trial}: finished answers from {finished}"
            pings = [c[0] for code, c, _ in frames if code == p.PING]
            assert set(pings) == {3}
            # Every ping was answered except one the line's quiet cut short.
            assert len(pings) >= pinged - 1, f"trial {trial}: {len(pings)} of {pinged} pings answered"
            assert sim3.state(1)["collisions"] == 0, f"trial {trial}"
