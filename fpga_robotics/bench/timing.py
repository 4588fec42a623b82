"""The timing primitives every benchmark uses: a stopwatch of wall and CPU time, no garbage
collection while timing, and the median/minimum/maximum of repeated measurements."""

import contextlib
import gc
import statistics
import time
from dataclasses import dataclass

__all__ = ["Spread", "Times", "gc_paused", "stopwatch"]


@dataclass(frozen=True)
class Spread:
    """Median, minimum and maximum of repeated measurements."""

    median: float
    min: float
    max: float
    n: int

    @classmethod
    def of(cls, values):
        values = list(values)
        if not values:
            raise ValueError("no measurements")
        return cls(statistics.median(values), min(values), max(values), len(values))

    def scaled(self, factor):
        return Spread(self.median * factor, self.min * factor, self.max * factor, self.n)

    def __format__(self, spec):
        """``median (min-max)`` in ``spec`` (``f"{s:.3f}"``)."""
        spec = spec or ".3g"
        return f"{self.median:{spec}} ({self.min:{spec}}-{self.max:{spec}})"


@dataclass
class Times:
    """Wall-clock and CPU seconds of a ``stopwatch`` block."""

    wall: float = 0.0
    cpu: float = 0.0


@contextlib.contextmanager
def stopwatch(cpu_clock=time.process_time):
    """``with stopwatch() as t: ...``; then ``t.wall`` and ``t.cpu`` in seconds. The CPU clock
    is the process's by default (threads of a library count); ``time.thread_time`` for the
    calling thread alone."""
    times = Times()
    start, cpu_start = time.perf_counter(), cpu_clock()
    try:
        yield times
    finally:
        times.wall = time.perf_counter() - start
        times.cpu = cpu_clock() - cpu_start


@contextlib.contextmanager
def gc_paused():
    """No garbage collection while timing: a collection would land in one frame's time."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
