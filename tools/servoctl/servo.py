"""One servo on a bus: every packet of the protocol as a method, values in
protocol units (0.1 degree, ms, mW) unless the name says otherwise."""
from . import frame, outcome
from . import protocol as p
from . import registers, stability, units
from .answers import Fault, Monitor, MotionSnapshot, StoreHealth
from .checks import check_range, scaled, to_ms
from .errors import BadAnswer, Refused, ServoError, ValueOutOfRange
from .move_request import MoveRequest


def _answers(read) -> bool:
    """read(), False when it goes unanswered."""
    try:
        return read()
    except p.NoReply:
        return False


class Servo:
    def __init__(self, bus: p.Bus, servo_id: int):
        self.bus = bus
        self.id = check_range("servo ID", servo_id, 0, 254)

    # ---- queries -------------------------------------------------------
    def ping(self, timeout=None) -> bool:
        """True if the servo answers within timeout (the bus's if None), asked
        twice if need be (Bus.request: it may be in a page erase)."""
        try:
            self.bus.request(p.PING, bytes([self.id]), timeout=timeout)
            return True
        except p.NoReply:
            return False

    def read(self, key) -> int:
        item = registers.find(key)
        content = self.bus.request(p.READ_DATA, bytes([self.id, item.id]))
        if len(content) < 2:
            raise BadAnswer(f"servo {self.id}: a ReadData answer of {len(content)} bytes, not 2 or more")
        data = content[2:]
        if len(data) != item.size:
            raise ServoError(f"servo {self.id} has no readable {item.name} ({item.id})")
        return item.unpack(data)

    def write(self, key, value: int, check: bool = True) -> None:
        """Writes one item; a drive or gain item (80-88) after the check that
        the loop stays stable (stability.py) unless check is False (the
        servo's own check still holds)."""
        item = registers.find(key)
        item.check(value)
        if check and item.name in stability.ITEMS:
            self.write_drive({item.name: value})
            return
        self._write(item, value)

    def write_drive(self, values: dict) -> None:
        """Drive and gain items (80-88, by name), each kept: refused, and
        nothing written, where the set they make would make the loop
        unstable; in an order in which each set along the way passes."""
        if not values:
            return
        now = {name: self.read(name) for name in stability.ITEMS}
        changes = {k: v for k, v in values.items() if now[k] != v}
        for name, value in stability.write_order(now, changes):
            self._write(registers.find(name), value)

    def _write(self, item, value: int) -> None:
        if item.name == "baud":  # read back only at the new rate: not sent again
            took = None
        elif item.name == "servo_id":  # read back at the new ID: by this servo's serial number
            took = self._is_at(value, self.read("serial"))
        else:
            took = lambda: self.read(item.id) == value  # noqa: E731
        if not self._write_kept(p.WRITE_DATA, bytes([self.id, item.id]) + item.pack(value), took):
            why = self.out_of_order(item, value)
            raise Refused(f"servo {self.id} refused {item.name} = {units.show(item, value) if item.quantity else value}"
                          f"{self._size_first(item, value) or (why and ': ' + why) or self._why_refused()}")

    def _is_at(self, new_id: int, serial: int):
        """A read-back: whether this servo (its serial number, read before
        the write) answers at new_id; not another servo that held new_id."""
        return lambda: _answers(lambda: Servo(self.bus, new_id).read("serial") == serial)

    def _write_kept(self, code: int, content: bytes, took) -> bool:
        """Sends a write (content, its result the answer's last field) and
        returns whether the servo took it. A write without an answer may have
        landed in a page erase: carried out, not answered
        (docs/decisions-hardware.md). took() then reads back whether the
        servo holds what was written; if not, the write is sent once more
        and its answer is the servo's word. A write that cannot be read back
        (took None) is not sent again: its NoReply says how many answers
        the servo counts as not sent (ReadStore)."""
        try:
            return p.decode_answer(code, self.bus.request(code, content))[-1] == 1
        except p.NoReply as lost:
            if took is None:
                raise self._unanswered(lost) from None
            try:
                if took():
                    return True
            except p.NoReply:  # the read went unanswered too: nobody there
                raise lost from None
        self.bus.sent_again += 1
        return p.decode_answer(code, self.bus.request(code, content, again=False))[-1] == 1

    def _unanswered(self, lost: p.NoReply) -> p.NoReply:
        """lost, with what ReadStore counts: requests carried out during a
        page erase and not answered, this one perhaps among them."""
        try:
            dropped = self.read_store().answers_dropped
        except p.LinkError:
            raise
        except ServoError:  # no answer, or not one this tool knows
            return lost
        return p.NoReply(f"{lost}; servo {self.id} answers now and counts {dropped} request(s) carried "
                         f"out during a page erase and not answered: this one may be among them "
                         f"(see 'servoctl store {self.id}')")

    def read_all(self) -> dict:
        content = self.bus.request(p.READ_BATCH, bytes([self.id]))
        return registers.decode_user_area(p.decode_answer(p.READ_BATCH, content)[1])

    def read_stored(self) -> dict:
        """The user area (one batch read) and the drive area (item by item);
        a servo without the drive items (the maker's firmware) gives the
        user area alone."""
        values = self.read_all()
        try:
            for item in registers.DRIVE:
                values[item.name] = self.read(item.id)
        except ServoError:
            return {k: v for k, v in values.items() if k not in {i.name for i in registers.DRIVE}}
        return values

    def write_all(self, values: dict) -> None:
        block = registers.encode_user_area(values)
        now = registers.decode_user_area(block)
        settable = [item.name for item in registers.USER if item.writable]

        at_new_id = self._is_at(now["servo_id"], self.read("serial"))

        def took():  # read back where the servo answers after it: at its new ID
            back = at_new_id() and _answers(lambda: Servo(self.bus, now["servo_id"]).read_all())
            return bool(back) and all(back[name] == now[name] for name in settable)
        if not self._write_kept(p.WRITE_BATCH, bytes([self.id]) + block, took):
            raise Refused(f"servo {self.id} refused the user area block{self._why_refused()}")

    def reset_user_data(self) -> None:
        if not self._write_kept(p.RESET_USER_DATA, bytes([self.id]), None):
            raise Refused(f"servo {self.id} refused the reset{self._why_refused()}")

    def out_of_order(self, item, value: int, said=units.show) -> str:
        """Why the servo refuses value of item for its pair's order
        (registers.ORDERED: angle_min below angle_max, low_voltage below
        high_voltage) against the other item now, values as said(item, raw)
        puts them; "" where it keeps the order (one read), or item is in no pair."""
        other = registers.pair_of(item.name)
        broken = other and registers.out_of_order(item.name, value, {other: (now := self.read(other))})
        if not broken:
            return ""
        way = "above" if broken[1] == "below" else "below"
        return (f"{item.name} must stay {broken[1]} {other} ({said(registers.find(other), now)} now): "
                f"set {other} {way} {said(item, value)} first")

    def _size_first(self, item, value: int) -> str:
        """": <why>" where value is beyond what the Cortex-M0 image takes
        (the schema's size_first_max) and this servo runs it (its board,
        from UpdateStatus); "" otherwise."""
        if not 0 <= item.size_first_max < value:
            return ""
        from . import image, update
        try:
            board = update.status(self.bus, self.id).board
        except p.LinkError:
            raise
        except ServoError:  # no answer, or not one this tool knows
            return ""
        if next((b.cpu for b in image.boards().values() if b.id == board), "") != "cortex-m0":
            return ""
        return f": it runs the Cortex-M0 image ({image.board_named(board)}). {item.size_first_why}"

    def _why_refused(self) -> str:
        """Why the servo's store refused the last change, from ReadStore:
        ": <reason>", or "" when the store took no part (a value out of range,
        a read-only item) or the servo has no ReadStore (the maker's)."""
        try:
            health = self.read_store()
        except p.LinkError:
            raise
        except ServoError:  # no answer, or not one this tool knows
            return ""
        reasons = [StoreHealth.ADVICE[name] for name in health.flag_names()]
        return ": " + "; ".join(reasons) if reasons else ""

    def angle(self) -> int:
        return p.decode_answer(p.READ_ANGLE, self.bus.request(p.READ_ANGLE, bytes([self.id])))[1]

    def multi_turn_angle(self):
        """(angle in 0.1 degree, turns)."""
        return p.decode_answer(p.READ_MULTI_TURN, self.bus.request(p.READ_MULTI_TURN, bytes([self.id])))[1:]

    def monitor(self) -> Monitor:
        return Monitor.decode(self.bus.request(p.MONITOR, bytes([self.id])))

    def read_motion(self) -> MotionSnapshot:
        """Needs this firmware: the maker's servos do not know packet 0x40."""
        return MotionSnapshot.decode(self.bus.request(p.READ_MOTION, bytes([self.id])))

    def read_store(self) -> StoreHealth:
        """Needs this firmware: the maker's servos do not know packet 0x41."""
        return StoreHealth.decode(self.bus.request(p.READ_STORE, bytes([self.id])))

    def read_fault(self, index: int) -> Fault:
        """Needs this firmware: index 0 is the newest."""
        check_range("fault index", index, 0, 255)
        return Fault.decode(self.bus.request(p.READ_FAULTS, bytes([self.id, index])))

    def faults(self) -> list:
        """The whole history, newest first."""
        first = self.read_fault(0)
        if first.what == 0:
            return []
        return [first] + [self.read_fault(i) for i in range(1, first.count)]

    def clear_faults(self) -> None:
        # Read back: the history is empty once cleared.
        if not self._write_kept(p.CLEAR_FAULTS, bytes([self.id]), lambda: self.read_fault(0).what == 0):
            raise Refused(f"servo {self.id} refused to clear its fault history: none kept, its "
                          f"wear budget allows no record now, or the history's page is full while "
                          f"the output is driven (release it, leave the bus quiet 100 ms, "
                          f"clear again)")

    def status(self) -> int:
        return self.read("status")

    # ---- motion ----------------------------------------------------------
    def _move(self, code: int, content: bytes, wait: bool):
        """Sends a motion command; with control response on and wait, waits
        for its answer (sent when the move has finished)."""
        self.bus.send(code, content)
        if wait:
            return self.bus.read_response(code, self.id, timeout=wait)
        return None

    def move(self, angle_decideg: int, interval_ms: int = None, velocity: int = None,
             acc_ms: int = 20, dec_ms: int = 20, power_mw: int = 0, multi_turn: bool = False,
             wait=False, ramps: bool = True):
        """An angle move: by interval with ramps (packets 11, 14) or without
        (ramps=False: 8, 13, which ramp 20 ms), or by velocity in 0.1 deg/s
        (12, 15). The packet as it is: the firmware takes a single-turn
        angle within the turn the horn is in. move_to checks first."""
        check_range("power", power_mw, 0, 65535, "mW")
        check_range("acceleration time", acc_ms, 0, 65535, "ms")
        check_range("deceleration time", dec_ms, 0, 65535, "ms")
        if multi_turn:
            check_range("angle", angle_decideg, *p.field_range(p.MULTI_TURN, "angle"), "deg", 10)
        else:
            check_range("angle", angle_decideg, *p.field_range(p.ANGLE, "angle"), "deg", 10)
        if (interval_ms is None) == (velocity is None):
            raise ValueOutOfRange("give either an interval or a velocity")
        if velocity is not None:
            code = p.MULTI_TURN_BY_VELOCITY if multi_turn else p.ANGLE_BY_VELOCITY
            check_range("speed", velocity, *p.field_range(code, "target_velocity"), "deg/s", 10)
            content = p.encode_request(code, self.id, angle_decideg, velocity, acc_ms, dec_ms, power_mw)
        elif not ramps:
            code = p.MULTI_TURN if multi_turn else p.ANGLE
            check_range("interval", interval_ms, *p.field_range(code, "interval"), "ms")
            content = p.encode_request(code, self.id, angle_decideg, interval_ms, power_mw)
        else:
            code = p.MULTI_TURN_BY_INTERVAL if multi_turn else p.ANGLE_BY_INTERVAL
            check_range("interval", interval_ms, *p.field_range(code, "interval"), "ms")
            content = p.encode_request(code, self.id, angle_decideg, interval_ms, acc_ms, dec_ms, power_mw)
        return self._move(code, content, wait)

    def send_move(self, angle_decideg: int, request: MoveRequest, wait=False):
        """move() with its profile and options as one MoveRequest."""
        return self.move(angle_decideg, interval_ms=request.interval_ms, velocity=request.velocity,
                         acc_ms=request.acc_ms, dec_ms=request.dec_ms, power_mw=request.power_mw,
                         multi_turn=request.multi_turn, wait=wait, ramps=request.ramps)

    def wheel(self, action: str, speed_dps: int = 0, value: int = 0, clockwise: bool = False, wait=False):
        """Wheel mode: action stop, run, turns (value turns) or time (value ms)."""
        actions = {"stop": 0, "run": 1, "turns": 2, "time": 3}
        if action not in actions:
            raise ValueOutOfRange(f"wheel action must be one of {', '.join(actions)}, not {action!r}")
        check_range("wheel speed", speed_dps, *p.field_range(p.WHEEL, "speed"), "deg/s")  # above: clamped
        check_range("wheel value", value, 0, 65535)
        method = actions[action] | (0x80 if clockwise else 0)
        return self._move(p.WHEEL, p.encode_request(p.WHEEL, self.id, method, speed_dps, value), wait)

    def damping(self, power_mw: int = 0) -> None:
        check_range("power", power_mw, 0, 65535, "mW")
        self.bus.send(p.DAMPING, p.encode_request(p.DAMPING, self.id, power_mw))

    def drive_duty(self, duty: float, ms: int) -> None:
        """Open loop (DriveDuty, this firmware's 0x46): the bridge at duty (-1..1
        of the supply) for ms (the range of DriveDuty's time), then released. The current limit and
        the protections hold it; the angle limits do not."""
        if not -1.0 <= duty <= 1.0:
            raise ValueOutOfRange(f"duty takes -1 to 1 (of the supply), not {duty!r}")
        check_range("time", ms, *p.field_range(p.DRIVE_DUTY, "time"), "ms")
        q15 = round(duty * 32767)
        if q15 == 0:
            raise ValueOutOfRange(f"duty {duty} rounds to 0 (1/32767 of the supply is the least)")
        self.bus.send(p.DRIVE_DUTY, p.encode_request(p.DRIVE_DUTY, self.id, q15, ms))

    def stop(self, mode: str = "release", power_mw: int = 0) -> None:
        modes = {"release": 0x10, "hold": 0x11, "damping": 0x12}
        if mode not in modes:
            raise ValueOutOfRange(f"stop mode must be one of {', '.join(modes)}, not {mode!r}")
        self.bus.send(p.STOP_ON_CONTROL, p.encode_request(p.STOP_ON_CONTROL, self.id, modes[mode], power_mw))

    def set_origin(self) -> None:
        self.bus.send(p.SET_ORIGIN, bytes([self.id, 0]))

    def reset_multi_turn(self) -> None:
        self.bus.send(p.RESET_MULTI_TURN, bytes([self.id]))

    # ---- engineering units: the documented Python API (docs/servoctl.md) ---
    def move_to(self, degrees: float, duration_s: float = None, speed_dps: float = None,
                accel_s: float = 0.02, decel_s: float = 0.02, power_w: float = 0.0,
                multi_turn: bool = False, wait: bool = False, tolerance_deg: float = 0.5):
        """Moves to an angle in degrees from the origin, in duration_s
        seconds or at speed_dps degrees per second (one of them; default
        1 s). Single-turn (-180..180) unless multi_turn: a target the move
        would not reach as asked (beyond a single turn, outside the angle
        limits, or a servo in another turn) raises before anything is sent
        (frame.py). With wait, returns when the horn has arrived within
        tolerance_deg, and raises Refused saying why when it does not
        (stalled, a protection, timed out)."""
        if duration_s is not None and speed_dps is not None:
            raise ValueOutOfRange("give a duration or a speed, not both")
        by_speed = speed_dps is not None
        request = MoveRequest(
            acc_ms=to_ms(accel_s, "accel_s"), dec_ms=to_ms(decel_s, "decel_s"),
            power_mw=scaled(power_w, 1000, "power_w"), multi_turn=multi_turn,
            velocity=scaled(speed_dps, 10, "speed_dps") if by_speed else None,
            interval_ms=None if by_speed else to_ms(1.0 if duration_s is None else duration_s, "duration_s"))
        asked = scaled(degrees, 10, "degrees")
        where = frame.check_target(self, asked, multi_turn)
        plan = outcome.plan_move(self, asked, request, where) if wait else None
        self.send_move(asked, request)
        outcome.taken(self, "the move")
        if not wait:
            return None
        result = outcome.wait_for_arrival(self, plan, tolerance_deg)
        if not result.arrived:
            raise Refused(f"servo {self.id}: {result.reason}")
        return result

    def position_deg(self) -> float:
        """The multi-turn angle, degrees."""
        return self.multi_turn_angle()[0] / 10.0

    def velocity_dps(self) -> float:
        """The horn's speed as the servo measures it, degrees per second."""
        return self.read_motion().velocity_decideg_s / 10.0

    def supply_v(self) -> float:
        return self.read("voltage") / 1000.0

    def current_a(self) -> float:
        return self.read("current") / 1000.0

    def power_w(self) -> float:
        return self.read("power") / 1000.0

    def temperature_c(self) -> float:
        from . import ntc

        return ntc.adc_to_celsius(self.read("temperature"))

    def status_names(self) -> list:
        """The status bits that are set, by name (registers.STATUS_BITS)."""
        return registers.status_names(self.status())

    def release(self) -> None:
        self.stop("release")

    def hold(self) -> None:
        self.stop("hold")
