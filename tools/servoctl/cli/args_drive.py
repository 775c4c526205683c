"""servoctl's bring-up commands on the command line: identify, calibrate,
tune. Each turns the horn through its travel, with the bridge driven open
loop: --past-limits says the horn is free where the angle limits are
narrowed (a joint's), else the command refuses (drive_guard.py)."""

PAST_LIMITS = "the horn is free: run though the angle limits are narrowed (the command turns it past them)"


def add_commands(sub) -> None:
    c = sub.add_parser("identify", help="the drive train's constants from open-loop duty steps (horn free)")
    c.add_argument("id", type=int)
    c.add_argument("--duty", type=float, default=0.45,
                   help="the largest duty, of the supply (default 0.45); four steps up to it, each way")
    c.add_argument("--step-ms", type=int, default=0,
                   help="each step's length (default: 12 rise times of a first step, 0.7-10 s)")
    c.add_argument("--mujoco", metavar="FILE",
                   help="also write a MuJoCo actuator model (MJCF) and say how closely it replays the steps")

    c = sub.add_parser("calibrate", help="the current amplifier's zero, the direction and the zero angle, "
                                         "found with the horn free and stored")
    c.add_argument("id", type=int)
    c.add_argument("--keep-zero", action="store_true",
                   help="leave the zero (item 90) as it is (else: the horn's position now becomes angle 0)")

    c = sub.add_parser("tune", help="identify, then the gains for a bandwidth with their margins; stored")
    c.add_argument("id", type=int)
    c.add_argument("--bandwidth", type=float, default=0.0, metavar="HZ",
                   help="the closed loop's natural frequency (default: 8 Hz, or 0.8 of what items 86-88 allow)")
    c.add_argument("--duty", type=float, default=0.45, help="identify's largest duty (default 0.45)")
    c.add_argument("--dry-run", action="store_true", help="only show the gains and margins: nothing written")
    for name in ("identify", "calibrate", "tune"):
        sub.choices[name].add_argument("--past-limits", action="store_true", help=PAST_LIMITS)
