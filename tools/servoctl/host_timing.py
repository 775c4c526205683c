"""A real host's timing, as a model for tests and benchmarks on a paced
simulator (docs/streaming.md, "On the host's timeline"): where a loop's
frame k, due at a moment on its period's grid, leaves the host. Python's
sleep, a loaded PC and a USB adapter move it by a few ms either way
(jitter_s, uniform); now and then one is a whole period late and leaves
with the next (late_every: one in that many; 0 never). A frame never
leaves before the one before it. Seeded: the same run every time."""
import random


class HostTiming:
    def __init__(self, jitter_s: float = 0.0, late_every: int = 0, seed: int = 67):
        if not 0 <= jitter_s <= 1.0 or late_every < 0:
            raise ValueError(f"a host's jitter is 0 to 1000 ms and its late frames one in 0 (none) or more, "
                             f"not {jitter_s * 1000:g} ms and {late_every}")
        self.jitter_s, self.late_every = jitter_s, late_every
        self._rng = random.Random(seed)
        self._last = None

    def leaves(self, k: int, due_s: float, period_s: float) -> float:
        """When frame k, due at due_s, leaves the host."""
        at = due_s + self._rng.uniform(-self.jitter_s, self.jitter_s) if self.jitter_s else due_s
        if self.late_every and k % self.late_every == self.late_every - 1:
            at = due_s + period_s
        if self._last is not None and at < self._last:
            at = self._last
        self._last = at
        return at

    def __bool__(self) -> bool:
        return bool(self.jitter_s or self.late_every)
