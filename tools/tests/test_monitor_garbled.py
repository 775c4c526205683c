"""A Sync Monitor answer cut short (a collision, a brown-out) read into the
next servo's answer makes a frame whose checksum holds now and then (1 in
256): it was taken as the first servo's state, angle -402 386 922 (0.1
deg), 10 268 turns. A Monitor answer's angle and turns have the multi-turn
range (protocol/servo_schema): such a frame is a bad answer, no state."""
from servoctl import group
from servoctl import protocol as p

# Servo 1's answer cut after 12 bytes, then servo 4's whole (its current, 40 mA, makes the checksum hold).
WIRE = bytes.fromhex("051c161001e81c7800f401d0051c161004e81c2800f401d00700d4feffff000013")


def test_a_garbled_monitor_frame_is_no_servos_state():
    bus = p.Bus("loop://", 1000000, timeout=0.05)
    bus.send(*group.monitor_request([1, 4]))
    bus.serial.write(WIRE)  # loop:// hands back what is written: the wire's bytes
    states = group.monitor_answers(bus, [1, 4])
    assert 1 not in states, states  # not the garbage; servo 4's header went into it
