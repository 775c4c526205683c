"""servoctl info: one servo's status area decoded, and this firmware's
safety items (the winding's temperature, what holds the output back, the
bus watchdog)."""
import json

from .. import ntc, registers
from ..errors import ServoError
from ..outcome import SAFE_MODE, in_safe_mode
from ..servo import MotionSnapshot, Servo


def cmd_info(bus, args):
    s = Servo(bus, args.id)
    m = s.monitor()
    if args.json:
        print(json.dumps({
            "id": args.id, "voltage_v": m.voltage_mv / 1000, "current_a": m.current_ma / 1000,
            "power_w": m.power_mw / 1000, "temperature_adc": m.temperature_adc,
            "temperature_c": ntc.celsius_or_none(m.temperature_adc, 2), "status": registers.status_names(m.status),
            "angle_deg": m.angle_decideg / 10, "turns": m.turns, "model": s.read("model"),
            "firmware": s.read("firmware"), "serial": s.read("serial"), **_safety(s)}))
        return 0
    print(f"servo {args.id}")
    print(f"  voltage      {m.voltage_mv / 1000:.2f} V")
    print(f"  current      {m.current_ma / 1000:.3f} A")
    print(f"  power        {m.power_mw / 1000:.2f} W")
    print(f"  temperature  {ntc.describe(m.temperature_adc)}")
    status = ", ".join(registers.status_names(m.status)) or "ok"
    print(f"  status       0x{m.status:02x}: {status}")
    print(f"  angle        {m.angle_decideg / 10:.1f} deg ({m.turns} turns)")
    print(f"  model        0x{s.read('model'):04x}")
    print(f"  firmware     0x{s.read('firmware'):04x}")
    print(f"  serial       0x{s.read('serial'):08x}")
    safety = _safety(s)
    if safety:
        print(f"  winding      {safety['winding_c']:.1f} degC (estimated; derating "
              f"{'on' if safety['derating'] else 'off'})")
        print(f"  limiter      {safety['limiter']}")
        print(f"  watchdog     {safety['watchdog']}")
    if safety.get("safe_mode"):
        print("  " + SAFE_MODE.format(where=f"'servoctl faults {args.id}' says which"))
    return 0


def _safety(s: Servo) -> dict:
    """This firmware's items 64-67 (and 75 where it is 1); none from a
    servo without them."""
    try:
        watchdog, action = s.read("watchdog_ms"), s.read("watchdog_action")
        safe = in_safe_mode(s)
        # Item 67 reads 7 (watchdog) in safe mode too: said as what holds it.
        return {"winding_c": s.read("winding_temperature") / 10, "derating": s.read("derating"),
                "limiter": "safe mode" if safe else MotionSnapshot.LIMITERS[s.read("limiter")],
                "watchdog": f"{watchdog} ms, then {_action(action)}" if watchdog else "off",
                "safe_mode": safe}
    except ServoError:
        return {}


def _action(value: int) -> str:
    """Item 65 by the schema's name for it ("hold"), which config set takes."""
    return registers.find("watchdog_action").name_of(value) or str(value)


# This module's commands on a bus, by name (cli/app.py's COMMANDS).
COMMANDS = {
    "info": cmd_info,
}
