"""The trapezoidal profile the firmware plans (motion/profile.c), in floating
point, for plotting a recorded move against its plan."""


def velocity_timing(distance, v0, vmax, acc, dec):
    """Phase lengths (ms) of a velocity-based move, as the firmware rounds
    them; distance in 0.1 deg, velocities in 0.1 deg per ms."""
    v = vmax if distance >= 0 else -vmax
    ramps = ((v0 + v) * acc + v * dec) / 2.0
    rest = distance - ramps
    if rest == 0 or (rest > 0) == (v > 0):
        return acc, int(abs(rest) / vmax + 0.5), dec
    if distance == 0 or (ramps > 0) != (distance > 0):
        return acc, 0, dec
    k = abs(distance) / abs(ramps)
    a, b = int(acc * k), int(dec * k)
    total = int((acc + dec) * k + 0.5)
    return a, max(0, total - a - b), b


def positions(start, target, acc, cruise, dec, v0=0.0):
    """Planned position (0.1 deg) at every ms from 0 to the end."""
    n1, nc, n3 = acc, cruise, dec
    den = n1 + 2 * nc + n3 or 2
    v = (2.0 * (target - start) - v0 * n1) / den
    p1 = start + (v0 + v) * n1 / 2.0
    out = []
    total = n1 + nc + n3
    for t in range(total + 1):
        if t < n1:
            out.append(start + v0 * t + (v - v0) * t * t / (2.0 * n1))
        elif t < n1 + nc:
            out.append(p1 + v * (t - n1))
        else:
            u = total - t
            out.append(target - (v * u * u / (2.0 * n3) if n3 else 0.0))
    return out


# Jerk-limited moves (item 70; motion/planning.c, profile.c): the trapezoid
# averaged over a window of T ticks (1 ms), which the move takes longer.
JERK_Q24 = 167          # 1 (deg/s^2)/ms in Q24 decideg per tick^3, as the firmware rounds it
MAX_WINDOW_MS = 4096    # PROFILE_MAX_SMOOTH


def _up_q24(a: float) -> int:
    return -int(-abs(a) * (1 << 24) // 1)


def smooth_window(distance, acc, cruise, dec, jerk_limit, v0=0.0) -> int:
    """The window T (ms) the firmware averages a trapezoid over for a jerk
    limit (item 70, (deg/s^2)/ms; 0: none); the phases as smoothed_phases
    gives them. profile_smooth_ticks: the least T that keeps every jump of
    the acceleration across a window within the limit, at most 4096."""
    if not jerk_limit or acc + dec == 0:
        return 0
    v = (2.0 * distance - v0 * acc) / (acc + 2 * cruise + dec)
    k1, k3 = (v - v0) / acc, v / dec  # the ramps' accelerations, 0.1 deg/ms^2
    a1, a3, both = _up_q24(k1), _up_q24(k3), _up_q24(k1 + k3)
    most = max(a1, a3)
    jerk = jerk_limit * JERK_Q24
    t = 0
    for _ in range(2):  # a window longer than the cruise spans both ramps' edges
        jump = both if t > cruise and both > most else most
        t = min(-(-jump // jerk), MAX_WINDOW_MS)
    return t


def smoothed_phases(acc, cruise, dec, jerk_limit) -> tuple:
    """A jerk limit makes every ramp at least a tick long (planning.c)."""
    if jerk_limit:
        acc, dec = acc + (acc == 0), dec + (dec == 0)
    return acc, cruise, dec


def smoothed(plan: list, window: int) -> list:
    """The positions of a plan (one a ms) averaged over window ms: the
    S-curve the firmware runs, window ms longer."""
    if window <= 0:
        return plan
    first, last, n = plan[0], plan[-1], len(plan)
    out, total = [], first * window
    for t in range(n + window):
        total += (plan[t] if t < n else last) - (plan[t - window] if t >= window else first)
        out.append(total / window)
    return out
