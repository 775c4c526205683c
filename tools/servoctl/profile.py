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
