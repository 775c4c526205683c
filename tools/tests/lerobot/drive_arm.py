"""Run by .venv-lerobot's Python (test_lerobot.py), not by pytest: the
maker's LeRobot plugin (lerobot-robot-viola, lerobot-motor-starai) as a user
runs it, against the port given. Prints one JSON line of what it saw:

    python drive_arm.py PORT CALIBRATION_DIR"""
import json
import sys
import time
from pathlib import Path

from lerobot_robot_viola.config_starai_viola import StaraiViolaConfig
from lerobot_robot_viola.starai_viola import StaraiViola

# Each joint's target in degrees; the gripper's on its 0-100 scale.
TARGETS_DEG = {f"Motor_{k}": 10.0 * k - 30.0 for k in range(6)}
GRIPPER = 60.0


def main(port, calibration_dir):
    robot = StaraiViola(StaraiViolaConfig(port=port, id="sim", calibration_dir=Path(calibration_dir),
                                          use_degrees=True))
    robot.connect(calibrate=False)  # pings the seven motors, releases them
    bus = robot.bus
    try:
        before = robot.get_observation()
        action = {f"{m}.pos": bus._degrees_to_position_unit(deg) for m, deg in TARGETS_DEG.items()}
        action["gripper.pos"] = GRIPPER
        sent = robot.send_action(action)
        gripper_deg = bus._position_unit_to_degrees(bus._denormalize_goal_value("gripper", GRIPPER))
        time.sleep(1.0)  # the plugin's own moves take 350 ms
        after = robot.get_observation()
        after_deg = {m: bus._position_unit_to_degrees(after[f"{m}.pos"]) for m in TARGETS_DEG}
    finally:
        robot.disconnect()
    print(json.dumps({"ids": {m: motor.id for m, motor in bus.motors.items()},
                      "before": before, "sent": sent, "after": after, "after_deg": after_deg,
                      "targets_deg": dict(TARGETS_DEG, gripper=gripper_deg)}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
