"""servoctl monitor: samples several servos (one Monitor each, or one Sync
Monitor for all) and shows them as a live table (rich) on a terminal, plain
rows or JSON lines otherwise, and as a live plot of angle, speed, current
and temperature against time (matplotlib), or a plot file at the end."""
from dataclasses import dataclass, asdict
import json
import math
import sys

from .. import group, ntc, registers
from ..protocol import NoReply
from ..errors import ServoError
from ..servo import MotionSnapshot, Servo


@dataclass
class Sample:
    t_s: float
    id: int
    angle_deg: float
    velocity_dps: float  # from two successive angles; NaN for a servo's first (JSON null)
    voltage_v: float
    current_a: float
    power_w: float
    temperature_c: float  # NaN without a sensor reading
    status: list
    limiter: str = ""     # what holds the output back (item 67); "" where not read

def _celsius(adc: int) -> float:
    celsius = ntc.celsius_or_none(adc)
    return float("nan") if celsius is None else celsius


class Sampler:
    def __init__(self, bus, ids, sync: bool):
        self.bus, self.ids, self.sync = bus, list(ids), sync
        self.last = {}
        self.t0 = bus.clock()

    def _limiter(self, servo_id: int) -> str:
        """Item 67 by name; "" from a servo without it (the maker's). One
        request more a servo, with --sync too (after its round)."""
        try:
            return MotionSnapshot.LIMITERS[Servo(self.bus, servo_id).read("limiter")]
        except (NoReply, ServoError):
            return ""

    def take(self) -> tuple:
        """One sample of every servo that answered, and {id: why} of those
        that did not (silent). Each sample is stamped with the time its
        answer arrived, so a host that falls behind bends neither the time
        axis nor the speed."""
        arrivals, silent, limiters = {}, {}, {}
        if self.sync:
            monitors = group.sync_monitor(self.bus, self.ids, arrivals=arrivals)
            silent = {i: f"servo {i}: no answer in its Sync Monitor slot" for i in self.ids if i not in monitors}
            # Monitor's answer has no limiter: read after the round, as alone.
            limiters = {servo_id: self._limiter(servo_id) for servo_id in monitors}
        else:
            monitors = {}
            for servo_id in self.ids:
                try:
                    monitors[servo_id] = Servo(self.bus, servo_id).monitor()
                except NoReply as e:  # a short answer (BadAnswer) too
                    silent[servo_id] = str(e)
                    continue
                arrivals[servo_id] = self.bus.arrived_at
                limiters[servo_id] = self._limiter(servo_id)
        out = []
        for servo_id, m in monitors.items():
            now = arrivals[servo_id] - self.t0
            angle = m.angle_decideg / 10.0
            before = self.last.get(servo_id)
            # A speed needs two answers in a row: none is better than a false 0.
            speed = (angle - before[1]) / (now - before[0]) if before and now > before[0] else math.nan
            self.last[servo_id] = (now, angle)
            out.append(Sample(round(now, 3), servo_id, angle, round(speed, 1), m.voltage_mv / 1000.0,
                              m.current_ma / 1000.0, m.power_mw / 1000.0, _celsius(m.temperature_adc),
                              registers.status_names(m.status), limiters.get(servo_id, "")))
        for servo_id in silent:
            self.last.pop(servo_id, None)
        return out, silent


def _table(samples: dict):
    from rich.table import Table

    t = Table(title="servoctl monitor (Ctrl-C stops)")
    for name in ("id", "angle deg", "deg/s", "V", "A", "W", "degC", "limit", "status"):
        t.add_column(name, justify="right" if name not in ("status", "limit") else "left")
    for servo_id in sorted(samples):
        s = samples[servo_id]
        if isinstance(s, str):  # silent: why, and no stale values
            t.add_row(str(servo_id), *[""] * 7, f"silent: {s}")
            continue
        t.add_row(str(s.id), f"{s.angle_deg:.1f}", _num(s.velocity_dps, ".0f"), f"{s.voltage_v:.2f}",
                  f"{s.current_a:.3f}", f"{s.power_w:.2f}", _num(s.temperature_c, ".1f"),
                  s.limiter or "-", ", ".join(s.status) or "ok")
    return t


def _num(value: float, fmt: str) -> str:
    """A value, or '-' where there is none (NaN)."""
    return "-" if math.isnan(value) else format(value, fmt)


def sample_json(s: Sample) -> str:
    """One JSON line; a value there is none of (NaN) is null."""
    return json.dumps({k: None if isinstance(v, float) and math.isnan(v) else v
                       for k, v in asdict(s).items()})


def _row(s: Sample) -> str:
    return (f"{s.id:>3} {s.angle_deg:>10.1f} {_num(s.velocity_dps, '.0f'):>7} {s.voltage_v:>6.2f} "
            f"{s.current_a:>6.3f} {s.power_w:>6.2f} {_num(s.temperature_c, '.1f'):>6} "
            f"{s.limiter or '-':>8}  {', '.join(s.status) or 'ok'}")


class Plot:
    """Angle, speed, current and temperature against time, one line per
    servo; shown live, or saved at the end (headless)."""

    PANELS = (("angle_deg", "angle, deg"), ("velocity_dps", "speed, deg/s"),
              ("current_a", "current, A"), ("temperature_c", "temperature, degC"))

    def __init__(self, live: bool):
        import matplotlib

        if not live:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        self.plt = plt
        self.live = live
        self.fig, self.axes = plt.subplots(len(self.PANELS), 1, sharex=True, figsize=(9, 9))
        for ax, (_, label) in zip(self.axes, self.PANELS):
            ax.set_ylabel(label)
            ax.grid(True, alpha=0.3)
        self.axes[-1].set_xlabel("time, s")
        self.lines = {}
        self.data = {}
        if live:
            plt.ion()
            plt.show(block=False)

    def add(self, samples: list):
        for s in samples:
            series = self.data.setdefault(s.id, {key: [] for key, _ in self.PANELS} | {"t": []})
            series["t"].append(s.t_s)
            for key, _ in self.PANELS:
                series[key].append(getattr(s, key))
            if s.id not in self.lines:
                self.lines[s.id] = [ax.plot([], [], label=f"servo {s.id}")[0] for ax in self.axes]
                self.axes[0].legend(loc="upper left")
            for line, (key, _) in zip(self.lines[s.id], self.PANELS):
                line.set_data(series["t"], series[key])
        if self.live:
            for ax in self.axes:
                ax.relim()
                ax.autoscale_view()
            self.plt.pause(0.001)

    def save(self, path: str):
        for ax in self.axes:
            ax.relim()
            ax.autoscale_view()
        self.fig.tight_layout()
        self.fig.savefig(path, dpi=100)


def has_display() -> bool:
    """A live plot window can open: a display server, or not Linux/BSD."""
    import os

    return not sys.platform.startswith(("linux", "freebsd")) or bool(
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def monitor(bus, ids, every_s: float, count: int, sync: bool, as_json: bool,
            plot: bool, plot_file: str):
    """Samples until count (0: until Ctrl-C). Returns {id: why} of the
    servos that never answered."""
    sampler = Sampler(bus, ids, sync)
    # A live plot needs its window first; a plot file is drawn at the end,
    # so sampling does not wait for the plotting library to load.
    figure = Plot(live=True) if plot else None
    taken = []
    tty = sys.stdout.isatty() and not as_json
    latest = {}  # id: the last Sample, or why it is silent
    never = {i: "" for i in ids}  # servos not heard yet: why
    n = 0
    live = None
    if tty:
        from rich.live import Live

        live = Live(_table(latest), refresh_per_second=10)
        live.start()
    elif not as_json:
        print(f"{'id':>3} {'angle deg':>10} {'deg/s':>7} {'V':>6} {'A':>6} {'W':>6} {'degC':>6} {'limit':>8}  status")
    try:
        while count == 0 or n < count:
            samples, silent = sampler.take()
            at = round(bus.clock() - sampler.t0, 3)
            for s in samples:
                latest[s.id] = s
                never.pop(s.id, None)
                if as_json:
                    print(sample_json(s), flush=True)
                elif not tty:
                    print(_row(s), flush=True)
            for servo_id, why in sorted(silent.items()):
                latest[servo_id] = why
                if servo_id in never:
                    never[servo_id] = why
                if as_json:
                    print(json.dumps({"t_s": at, "id": servo_id, "silent": True, "why": why}), flush=True)
                elif not tty:
                    print(f"{servo_id:>3} silent: {why}", flush=True)
            if live is not None:
                live.update(_table(latest))
            if figure is not None:
                figure.add(samples)
            taken.extend(samples)
            n += 1
            bus.sleep(every_s)
    finally:
        if live is not None:
            live.stop()
        if plot_file:
            if figure is None:
                figure = Plot(live=False)
                figure.add(taken)
            figure.save(plot_file)
    return never
