"""Python model of ``UltrasoundDriver`` and of the interlock of ``FollowTargetSafe`` (pure
Python, no Amaranth), written from docs/sensor_designs.md rather than from the gateware.

Edges are numbered as in ``sim/pins/base.py``: edge 0 is the reset. An echo pulse is given
as ``(a, b)``: ECHO is sampled high at edges ``a .. b - 1``.
"""

from dataclasses import dataclass

from fpga_robotics.hw.sensor_params import DISTANCE_NONE, InterlockParams, UltrasoundParams

__all__ = ["InterlockModel", "Measurement", "UltrasoundModel", "echo_cycles_of"]


def echo_cycles_of(distance_mm, sound_mm_per_s, clock_hz):
    """The echo of a surface ``distance_mm`` away, in whole clock cycles (rounded to the
    nearest): ``2 * distance / sound`` seconds at ``clock_hz``."""
    return round(2 * distance_mm * clock_hz / sound_mm_per_s)


@dataclass(frozen=True)
class Measurement:
    """One measurement: shown (``measured`` high) right after edge ``edge``."""

    edge: int
    distance_mm: int
    no_echo: bool


class UltrasoundModel:
    """Trigger timing and the measurement of each period, from the echo pulses."""

    def __init__(self, params=None):
        self.params = UltrasoundParams() if params is None else params

    def trigger(self, k):
        """``(rise, fall)`` of trigger ``k`` (0 first): TRIG is high right after edges
        ``rise .. fall - 1``, i.e. it rises after edge ``rise`` and falls after edge ``fall``."""
        p = self.params
        rise = k * p.period_cycles + 1
        return rise, rise + p.trigger_cycles

    def distance(self, cycles):
        """``distance_mm`` for an echo of ``cycles`` cycles, in the counter's width."""
        p = self.params
        count = cycles % (1 << p.counter_bits)
        return (count * p.distance_k) >> p.distance_shift

    def measure(self, k, pulses):
        """The measurement of period ``k`` given every echo pulse ``(a, b)`` (sorted, apart).

        The echo is seen ``2`` edges after it starts (synchroniser); the first pulse seen
        within ``wait_cycles`` edges after TRIG falls is measured.
        """
        p = self.params
        if not p.echo_active_high:
            pulses = _complement(pulses)
        _, fall = self.trigger(k)
        first, last = fall + 1, fall + p.wait_cycles
        for a, b in pulses:
            if first <= a + 2 <= last:
                width = b - a
                if p.counter_bits >= p.full_echo_bits and width > p.max_echo_cycles:
                    return Measurement(a + p.max_echo_cycles + 2, DISTANCE_NONE, True)
                return Measurement(b + 2, self.distance(width), False)
        return Measurement(last, DISTANCE_NONE, True)

    def measurements(self, periods, pulses):
        return [self.measure(k, pulses) for k in range(periods)]


def _complement(pulses, end=1 << 62):
    """The low stretches between ``pulses`` (what an inverted ECHO looks like), from edge 1."""
    out, start = [], 1
    for a, b in sorted(pulses):
        if a > start:
            out.append((start, a))
        start = b
    out.append((start, end))
    return out


class InterlockModel:
    """The obstacle interlock: ``step(measurement)`` returns ``obstacle`` after it (shown one
    edge after the measurement's)."""

    def __init__(self, params=None):
        self.params = InterlockParams() if params is None else params
        self.obstacle = False

    def step(self, measurement):
        p = self.params
        if not measurement.no_echo and measurement.distance_mm < p.stop_mm:
            self.obstacle = True
        elif measurement.no_echo or (p.release_on_far and measurement.distance_mm >= p.resume_mm):
            # (Without release_on_far, the seeded bug, a far measurement does not release.)
            self.obstacle = False
        return self.obstacle
