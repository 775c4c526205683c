"""A servo made a joint for a test: its angle limits narrowed to +-limit
(0.1 deg), its horn moved to at (0.1 deg) and released there; on the
simulator's clock."""
from servoctl.servo import Servo


def narrowed_at_rest(sim, servo_id: int, limit: int, at: int) -> int:
    """The servo's reading where it rests (0.1 deg)."""
    with sim.bus(timeout=0.2) as bus:
        s = Servo(bus, servo_id)
        s.write("soft_start_on", 0)
        s.write("angle_max", limit)
        s.write("angle_min", -limit)
        s.move(at, interval_ms=400)
        sim.sleep(0.7)
        s.stop("release")
        sim.sleep(0.2)
        return s.read_motion().angle_decideg
