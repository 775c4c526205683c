#!/usr/bin/env python3
"""Writes the fuzz seed corpus for fuzz_servo.c: a setup byte, then
operations (the format is fuzz_servo.c's header comment). The protocol seeds
put every packet on the wire; the servo seeds also move the clock, the horn,
the sensors, the flash and the power, so that motion, protection and the
config store are reached: moves to completion and their answers, wheel
modes, hold and damping, stall (a held horn, a horn pushed back), every
monitor tripping and clearing, a move refused under a fault, encoder wrap,
page rotation, failed and cut saves, reloads. Run it after changing the
protocol or the harness; the output is committed."""
import pathlib
import struct

OUT = pathlib.Path(__file__).with_name("corpus")


def frame(header: bytes, code: int, content: bytes) -> bytes:
    if header == b"\x12\x4c" and len(content) >= 255:
        body = header + bytes([code, 0xFF]) + struct.pack("<H", len(content)) + content
    else:
        body = header + bytes([code, len(content)]) + content
    return body + bytes([sum(body) % 256])


def req(code: int, content: bytes) -> bytes:
    return frame(b"\x12\x4c", code, content)


def resp(code: int, content: bytes) -> bytes:
    return frame(b"\x05\x1c", code, content)


FACTORY = bytes([1, 0, 0, 0, 5, 0]) + struct.pack(
    "<HHHHHH", 10000, 4000, 8400, 651, 10000, 4000) + bytes([0, 0, 0, 0, 1, 1]) + struct.pack(
    "<Hhhh", 3000, 1350, -1350, 0)
assert len(FACTORY) == 32

SEEDS = {
    "ping": req(1, b"\x00"),
    "reset": req(2, b"\x00"),
    "read_every_item": b"".join(req(3, bytes([0, i])) for i in list(range(1, 9)) + list(range(32, 54))
                               + list(range(64, 73)) + list(range(80, 92))),
    "write_items": req(4, b"\x00\x21\x01") + req(4, b"\x00\x32\xe8\x03") + req(4, b"\x00\x35\x10\x00"),
    "write_id_and_baud": req(4, b"\x00\x22\x07") + req(1, b"\x07") + req(4, b"\x07\x24\x08"),
    "batch": req(5, b"\x00") + req(6, b"\x00" + FACTORY),
    "wheel": req(7, struct.pack("<BBHH", 0, 0x82, 90, 3)),
    "angle": req(8, struct.pack("<BhHH", 0, 900, 500, 0)),
    "damping": req(9, struct.pack("<BH", 0, 500)),
    "read_angles": req(10, b"\x00") + req(16, b"\x00"),
    "angle_interval": req(11, struct.pack("<BhHHHH", 0, 1000, 1000, 100, 200, 0)),
    "angle_velocity": req(12, struct.pack("<BhHHHH", 0, 200, 3000, 100, 200, 0)),
    "multi_turn": req(13, struct.pack("<BiIH", 0, -3686400, 4096000, 0)),
    "multi_turn_interval": req(14, struct.pack("<BiIHHH", 0, 7200, 5000, 20, 30, 0)),
    "multi_turn_velocity": req(15, struct.pack("<BiHHHH", 0, 7200, 7500, 50, 60, 0)),
    "reset_turns_origin": req(24, b"\x00\x10\x00\x00") + req(17, b"\x00") + req(23, b"\x00\x00"),
    "async": req(18, b"") + req(8, struct.pack("<BhHH", 0, 900, 500, 0)) + req(19, b"\x00"),
    "monitor": req(22, b"\x00"),
    "read_motion": req(11, struct.pack("<BhHHHH", 0, 900, 300, 100, 100, 0)) + req(0x40, b"\x00"),
    "control_response": req(4, b"\x00\x21\x01") + req(11, struct.pack("<BhHHHH", 0, 1000, 1000, 100, 200, 0)),
    "sync_monitor": req(25, bytes([22, 1, 4, 5, 6, 0, 9])) + resp(22, bytes(16)) + resp(22, bytes(16)),
    # Listed first: its header goes out before its build (servo.c, send_ahead),
    # while the host's bytes go on.
    "sync_monitor_first": req(25, bytes([22, 1, 4, 0, 6, 5, 9])) + resp(22, bytes(16)),
    "sync_move": req(25, bytes([8, 7, 2]) + struct.pack("<BhHH", 4, 0, 0, 0) + struct.pack("<BhHH", 0, 900, 500, 0)),
    "sync_long": req(25, bytes([14, 15, 200]) + b"".join(
        struct.pack("<BiIHHH", (k + 1) % 255, k * 10, 1000, 20, 20, 0) for k in range(200))),
    "stream_setpoints": req(0x45, struct.pack("<BihH", 0, 900, 500, 0)) + req(4, b"\x00\x45\x0a\x00")
                        + req(0x45, struct.pack("<BihH", 0xFF, -3686400, -7500, 65535))
                        + req(25, bytes([0x45, 9, 2]) + struct.pack("<BihH", 0, 100, 0, 20)
                              + struct.pack("<BihH", 4, 100, 0, 20)),
    "others_responses": resp(3, req(1, b"\x00")) + req(1, b"\x00"),
    "bad_checksum": req(1, b"\x00")[:-1] + b"\x00" + req(1, b"\x00"),
}


# Setup byte: flash image (0 blank, 1 used with soft start off, 2 used with
# its page one record from full, 3 used and answering moves), bytes between
# main-loop passes, slow UART.
BLANK, USED, PAGE_FULL, ANSWERING = 0, 1, 2, 3
SLOW_UART = 0x10


def wire(stream: bytes) -> bytes:
    out = b""
    for k in range(0, len(stream), 32):
        chunk = stream[k:k + 32]
        out += bytes([(len(chunk) - 1) << 3 | 0]) + chunk
    return out


def ms(t: int) -> bytes:
    out = b""
    while t > 0:
        step = min(t, 16)
        out += bytes([(step - 1) << 3 | 1])
        t -= step
    return out


def ms_fine(t: int) -> bytes:
    """t ms with a pass each 100 us."""
    out = b""
    while t > 0:
        step = min(t, 16)
        out += bytes([(16 | step - 1) << 3 | 1])
        t -= step
    return out


FOLLOW, SPIN, HELD = 1, 0, 2


def horn(mode: int, counts_per_tick: int = 0) -> bytes:
    return bytes([mode << 3 | 2, counts_per_tick & 0xFF])


def sensors(supply_mv: int, current_ma: int, ntc: int) -> bytes:
    return bytes([3, supply_mv // 40, current_ma // 20, ntc // 16])


HEALTHY = sensors(7400, 200, 2048)


def flash(dead: bool = False, cut_at: int = None, mode: int = 0) -> bytes:
    n = (1 if dead else 0) | (2 if cut_at is not None else 0) | mode << 2
    return bytes([n << 3 | 4]) + (bytes([cut_at]) if cut_at is not None else b"")


POWER_CYCLE = bytes([5])
# The resets a board can report (fuzz_servo.c, op 5), with their place in a row.
RESETS = {"firmware_fault": 1, "watchdog": 2, "software": 3, "brown_out": 4, "pin": 5,
          "low_power": 6, "planned": 7}


def reset(kind: str, in_row: int = 1) -> bytes:
    return bytes([(RESETS[kind] | (in_row - 1) << 3) << 3 | 5])


def stall_main_loop(t_ms: int) -> bytes:
    return bytes([(t_ms // 50 - 1) << 3 | 6])


def move(angle: int, interval: int, power: int = 0) -> bytes:
    return req(8, struct.pack("<BhHH", 0, angle, interval, power))


def stream(angle: int, velocity: int, host_ms: int) -> bytes:
    return req(0x45, struct.pack("<BihH", 0, angle, velocity, host_ms & 0xFFFF))


def write(item: int, value: int, size: int = 1) -> bytes:
    return req(4, bytes([0, item]) + value.to_bytes(size, "little", signed=value < 0))


SERVO_SEEDS = {
    "move_to_completion": (USED, wire(move(900, 200)) + ms(400) + wire(req(0x40, b"\x00"))),
    "move_answered": (ANSWERING, wire(move(-450, 100)) + ms(300) + wire(req(3, b"\x00\x05"))),
    "queued_moves_answered": (ANSWERING, wire(move(300, 60) + move(0, 60) + move(600, 60)) + ms(400)),
    # Each answer in its window: the quiet before it, then the servo's slot.
    "finished_moves_answer_in_their_slot": (ANSWERING, wire(move(300, 40) + move(0, 40)) + ms_fine(400)),
    "queue_full": (ANSWERING, wire(b"".join(move(100 * k, 50) for k in range(10))) + ms(100)),
    "velocity_moves": (USED, wire(req(12, struct.pack("<BhHHHH", 0, 200, 3000, 100, 200, 0))) + ms(200)
                       + wire(req(15, struct.pack("<BiHHHH", 0, -7200, 7500, 50, 60, 0))) + ms(600)),
    "interval_moves": (USED, wire(req(11, struct.pack("<BhHHHH", 0, 1000, 300, 100, 100, 0))) + ms(150)
                       + wire(req(14, struct.pack("<BiIHHH", 0, 3600, 200, 20, 30, 0))) + ms(400)),
    "preempted": (USED, wire(move(1800, 500)) + ms(100) + wire(move(-1800, 300)) + ms(100)
                  + wire(req(13, struct.pack("<BiIH", 0, 36000, 400, 0))) + ms(500)),
    # A 50 Hz stream at 250 deg/s, then silence (it brakes to a hold), then
    # the period told (item 69) and a setpoint at rest far away.
    "stream_then_late": (USED, b"".join(wire(stream(50 * k, 2500, 20 * k)) + ms(20) for k in range(12))
                         + ms(120) + wire(write(69, 30, 2) + stream(-900, 0, 400)) + ms(300)),
    # Streams within and at the limits: a gentle 50 Hz ramp the cubic follows,
    # a setpoint at the angle limit whose end speed would run on past it (a
    # 1 s period from the stamps), a step beyond the speed, the limits off and
    # a setpoint 2000 deg away, then item 48 = 2 and a multi-turn move past
    # the limits.
    "stream_within_and_at_the_limits": (USED, horn(FOLLOW)
                                        + b"".join(wire(stream(10 * k, 500, 20 * k)) + ms(20) for k in range(15))
                                        + wire(stream(1350, 7500, 1300)) + ms(300)
                                        + wire(stream(1000, -6000, 2300)) + ms(60)
                                        + wire(stream(0, 0, 2320)) + ms(100)
                                        + wire(write(48, 0) + stream(20000, 0, 2340)) + ms(200)
                                        + wire(write(48, 2) + req(13, struct.pack("<BiIH", 0, 3000, 300, 0)))
                                        + ms(400) + wire(req(0x40, b"\x00"))),
    # Jerk-limited moves (item 70): from rest, over the moving setpoint (a
    # velocity move 200 ms in), a short stroke, to their ends.
    "jerk_limited_moves": (USED, wire(write(70, 20, 2) + req(11, struct.pack("<BhHHHH", 0, 900, 400, 100, 100, 0)))
                           + ms(200) + wire(req(12, struct.pack("<BhHHHH", 0, -300, 3000, 50, 80, 0))) + ms(700)
                           + wire(req(12, struct.pack("<BhHHHH", 0, -200, 3000, 100, 200, 0))) + ms(900)
                           + wire(req(0x40, b"\x00"))),
    # Open loop (DriveDuty): a step that ends by itself, one damping takes
    # over, and the refused ones (no time, too long, no duty).
    "open_loop": (USED, wire(req(0x46, struct.pack("<BhH", 0, 9830, 40)) + req(0x40, b"\x00")) + ms(60)
                  + wire(req(0x46, struct.pack("<BhH", 0, -32768, 5000))) + ms(30)
                  + wire(req(9, struct.pack("<BH", 0, 800))) + ms(30)
                  + wire(req(0x46, struct.pack("<BhH", 0, 100, 0)) + req(0x46, struct.pack("<BhH", 0, 100, 10001))
                         + req(0x46, struct.pack("<BhH", 0, 0, 100)))),
    # The drive train as data: a written drive item changes the feed-forward
    # at once, a negative ratio drives the bridge the other way (closed loop
    # and open loop), and an out-of-range gain is refused.
    "drive_items": (USED, wire(write(86, 700, 2) + write(82, -345, 2) + write(80, 6400, 2)
                                + write(86, 1024, 2) + move(600, 200)) + ms(250)
                    + wire(req(0x46, struct.pack("<BhH", 0, 6000, 30))) + ms(40)
                    + wire(write(82, 345, 2) + write(91, 12, 2) + write(90, 2000, 2)) + ms(20)),
    "unstable_drive_item": (USED, wire(write(81, 37140, 2) + req(0x41, b"\x00") + write(72, 50, 2)
                                       + write(82, 3450, 2) + write(87, 80, 2) + move(450, 300)) + ms(200)),
    "wheel_run_stop": (USED, wire(req(7, struct.pack("<BBHH", 0, 0x01, 300, 0))) + ms(100)
                       + wire(req(7, struct.pack("<BBHH", 0, 0x00, 0, 0))) + ms(60)
                       + wire(write(47, 1) + req(7, struct.pack("<BBHH", 0, 0x81, 90, 0))) + ms(60)
                       + wire(req(7, struct.pack("<BBHH", 0, 0x80, 0, 0))) + ms(60)),
    "wheel_time_turns": (USED, wire(req(7, struct.pack("<BBHH", 0, 0x03, 200, 150))) + ms(250)
                         + wire(req(7, struct.pack("<BBHH", 0, 0x82, 750, 1))) + ms(700)),
    "hold_and_damping": (USED, wire(move(900, 300)) + ms(100) + wire(req(24, b"\x00\x11\x00\x00"))
                         + ms(50) + wire(req(9, struct.pack("<BH", 0, 800))) + horn(SPIN, 20) + ms(60)
                         + wire(req(24, b"\x00\x12\x00\x00")) + ms(30) + wire(req(24, b"\x00\x10\x00\x00"))
                         + ms(10) + wire(req(17, b"\x00") + req(23, b"\x00\x00")) + horn(FOLLOW)),
    "stall_held_horn": (USED, horn(HELD) + wire(move(900, 200, 3000)) + ms(1040)
                        + wire(req(3, b"\x00\x05")) + horn(FOLLOW) + ms(60)),
    "stall_releases": (USED, wire(write(37, 1)) + horn(HELD) + wire(move(-900, 200)) + ms(1040)
                       + wire(move(0, 100)) + horn(FOLLOW) + ms(60)),
    "pushed_backwards": (USED, wire(move(300, 100)) + ms(100) + horn(SPIN, -30) + ms(1040)),
    "encoder_wrap": (USED, horn(SPIN, 100) + ms(300) + horn(SPIN, -120) + ms(300)
                     + wire(req(16, b"\x00"))),
    "low_voltage_refuses": (USED, sensors(3000, 100, 2048) + ms(30) + wire(move(900, 200)) + ms(30)
                            + HEALTHY + ms(200) + wire(move(900, 100)) + ms(200)),
    "high_voltage": (USED, wire(move(900, 400)) + ms(50) + sensors(9600, 100, 2048) + ms(50)
                     + HEALTHY + ms(200)),
    "over_current_power": (USED, wire(move(900, 400)) + ms(50) + sensors(7400, 5000, 2048) + ms(50)
                           + HEALTHY + ms(200)),
    "over_temperature": (USED, wire(move(900, 400)) + ms(50) + sensors(7400, 200, 500) + ms(50)
                         + HEALTHY + ms(150) + sensors(7400, 200, 800) + ms(150)),
    "supply_sag_during_move": (USED, wire(move(1800, 600)) + ms(100) + sensors(5000, 300, 2048)
                               + ms(100) + sensors(8200, 300, 2048) + ms(300)),
    # A save settles 50 ms, then programs a write block a pass (24 here,
    # a pass per ms): 80 ms after a write it has landed.
    "page_rotation_and_reload": (PAGE_FULL, wire(write(38, 1234, 2)) + ms(80) + wire(write(44, 1))
                                 + ms(80) + POWER_CYCLE + wire(req(3, b"\x00\x26")) + ms(5)),
    "erase_ahead_when_quiet": (PAGE_FULL, wire(write(38, 1234, 2)) + ms(80) + wire(move(900, 150))
                               + wire(write(44, 1)) + ms(200) + wire(req(0x41, b"\x00")) + ms(120)),
    "cut_save_on_the_new_page": (PAGE_FULL, wire(write(38, 1234, 2)) + ms(80) + flash(cut_at=5, mode=1)
                                 + wire(write(44, 1)) + ms(80) + POWER_CYCLE + ms(5)),
    "failed_save_refuses": (USED, flash(dead=True) + wire(write(43, 2000, 2)) + ms(55)
                            + wire(write(43, 3000, 2) + req(2, b"\x00") + req(0x41, b"\x00"))
                            + flash(dead=False) + ms(1001) + wire(write(43, 3000, 2)) + ms(80)),
    "cut_mid_save": (PAGE_FULL, flash(cut_at=3, mode=2) + wire(write(50, 500, 2)) + ms(80) + POWER_CYCLE
                     + wire(write(50, 600, 2)) + ms(80) + POWER_CYCLE + wire(req(3, b"\x00\x32"))),
    "power_on_lock": (USED, wire(write(46, 1)) + ms(80) + POWER_CYCLE + ms(20)),
    # AssignId (0x42) to the harness's serial number (hal_double.c), then to another.
    "assign_id_by_serial": (USED, wire(req(0x42, bytes.fromhex("ff7856341207"))) + ms(80)
                            + wire(req(0x42, bytes.fromhex("ff7956341208")) + req(1, b"\x07")) + ms(5)),
    "main_loop_stalled": (USED, wire(move(900, 300)) + ms(50) + stall_main_loop(200) + ms(50)),
    "async_then_go": (USED, wire(req(18, b"") + move(900, 100) + req(19, b"\x00")) + ms(200)
                      + wire(req(18, b"") + move(0, 100) + req(19, b"\x01")) + ms(20)),
    "soft_start": (BLANK, wire(move(900, 100)) + ms(300)),
    "faster_than_the_planner": (USED, wire(req(13, struct.pack("<BiIH", 0, 3686400, 40, 0))) + ms(50)
                                + wire(req(24, b"\x00\x11\x00\x00")) + ms(20)),
    "velocity_move_to_here": (USED, wire(req(12, struct.pack("<BhHHHH", 0, 0, 3000, 100, 200, 0)))
                              + ms(50)),
    "slow_uart_sync": (USED | SLOW_UART | 1 << 2, wire(req(25, bytes([22, 1, 3, 5, 0, 9]))) + ms(10)
                       + wire(resp(22, bytes(16))) + ms(10)),
    # The bus watchdog (64, 65): each action, what item 67 and ReadMotion say, a
    # move that clears it; a move past the angle limit (67 = angle).
    "watchdog_release": (USED, wire(write(64, 30, 2) + write(65, 2) + move(900, 200)) + ms(60)
                         + wire(req(3, b"\x00\x43") + req(0x40, b"\x00") + move(1800, 100)) + ms(150)
                         + wire(req(0x40, b"\x00") + req(3, b"\x00\x43"))),
    "watchdog_hold_then_damp": (USED, wire(write(64, 20, 2) + write(65, 0) + move(900, 100)) + ms(40)
                                + wire(write(65, 1) + move(0, 100)) + ms(40) + wire(write(64, 0, 2))
                                + ms(5)),
    # The fault history (0x43, 0x44): faults with their readings, read back
    # across a power cycle, cleared; the supply and heat held back (67).
    "faults_read_and_cleared": (USED, wire(move(900, 300)) + sensors(3000, 100, 2048) + ms(150)
                                + wire(req(0x40, b"\x00") + req(3, b"\x00\x43")) + HEALTHY + ms(250)
                                + sensors(7400, 200, 500) + ms(100) + wire(req(3, b"\x00\x43")) + HEALTHY
                                + ms(250) + POWER_CYCLE + ms(5)
                                + wire(req(0x43, b"\x00\x00") + req(0x43, b"\x00\x01")
                                       + req(0x43, b"\x00\x09") + req(0x44, b"\x00")) + ms(40)
                                + POWER_CYCLE + ms(5)),
    "fault_with_a_dead_flash": (USED, flash(dead=True) + sensors(3000, 100, 2048) + ms(150) + HEALTHY
                                + ms(250) + flash(dead=False) + sensors(9600, 100, 2048) + ms(150)
                                + HEALTHY + ms(100) + wire(req(0x43, b"\x00\x00"))),
    # The servo's own resets (item 73's counts, the fault history), then safe
    # mode after the third in a row, which a move cannot leave.
    "own_resets_logged": (USED, wire(move(900, 300)) + ms(100) + reset("watchdog") + ms(5)
                          + wire(req(0x43, b"\x00\x00") + req(3, b"\x00\x49")) + ms(10)
                          + reset("brown_out") + ms(5) + reset("firmware_fault", 2) + ms(20)
                          + wire(req(0x43, b"\x00\x01")) + ms(10)),
    "own_resets_safe_mode": (USED, reset("firmware_fault", 3) + ms(5) + wire(move(900, 100)) + ms(120)
                             + wire(req(3, b"\x00\x4b") + req(0x44, b"\x00") + move(-900, 100)) + ms(60)
                             + reset("pin", 4) + ms(5) + reset("planned") + wire(move(450, 50)) + ms(60)),
    "hot_case_derates": (USED, wire(move(900, 400)) + sensors(7400, 3000, 720) + ms(300)
                         + wire(write(66, 0) + req(3, b"\x00\x44")) + ms(100) + wire(write(66, 1))
                         + ms(100) + HEALTHY + ms(100)),
}


def main() -> None:
    OUT.mkdir(exist_ok=True)
    for old in OUT.glob("*.bin"):
        old.unlink()
    for name, stream in SEEDS.items():
        # Blank flash, a pass after every byte, fast UART.
        (OUT / f"{name}.bin").write_bytes(bytes([BLANK]) + wire(stream))
    for name, (setup, ops) in SERVO_SEEDS.items():
        (OUT / f"{name}.bin").write_bytes(bytes([setup]) + ops)
    print(f"wrote {len(SEEDS) + len(SERVO_SEEDS)} seeds to {OUT}")


if __name__ == "__main__":
    main()
