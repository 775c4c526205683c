"""servo_sim's wire while a servo's CPU is held by a flash erase: its
answer leaves when the erase ends, and until then the wire is free. The
simulator booked the answer on the wire when the request came, 40 ms
ahead, and queued the host's bytes behind it: a STOP ALL sent during an
update's page erase reached a turning wheel 35-40 ms late (servoctl ui's
figure for it, and none of it the ui's). Now the host's bytes go on the
wire at once. The requests go out at simulated times (hostsend), on a
simulator that stands still while the host is away (paced)."""
import struct

from servoctl import protocol as p
from servoctl import update as upd
from servoctl.servo import Servo
from servoctl.sim import Simulator

ERASE_MS = 40  # the F1's page erase, the simulator's flash stall (RM0008: tERASE)


def test_a_stop_sent_during_another_servos_erase_is_on_the_wire_at_once(tmp_path):
    with Simulator(ids=[1, 2], state_dir=str(tmp_path / "state"), paced=True) as sim:
        with sim.bus(timeout=0.3) as bus:
            wheel = Servo(bus, 1)
            wheel.write("soft_start_on", 0)
            wheel.wheel("run", 120)
            upd.enter_bootloader(bus, 2)
            erase = p.request_frame(upd.UPDATE_ERASE, bytes([2]) + struct.pack("<H", 0))
            stop = p.request_frame(p.STOP_ON_CONTROL, p.encode_request(p.STOP_ON_CONTROL, 0xFF, 0x10, 0))
            t_ms = round(sim.clock_s() * 1000) + 50
            stop_ms = t_ms + 8  # inside servo 2's erase, its answer booked
            assert sim.control(f"hostsend {t_ms} {erase.hex()}").strip() == "ok"
            sim.sleep(t_ms / 1000.0 + 0.004 - sim.clock_s())  # the erase taken, its answer booked
            assert sim.control(f"hostsend {stop_ms} {stop.hex()}").strip() == "ok"
            sim.sleep(t_ms / 1000.0 + 0.2 - sim.clock_s())
            state = sim.state(1)
        stop_end_ms = stop_ms + len(stop) * 10 / 115.2
        assert stop_end_ms <= state["coasted_ms"] <= stop_end_ms + 2, \
            f"STOP's last byte at {stop_end_ms:.2f} ms, the wheel released at {state['coasted_ms']:.2f} ms"
        assert state["collisions"] == 0
