"""Elaboration parameters of the LIDAR designs: ``NearestObstacle`` (``NearestParams``) and
the corridor follower built on it (``CorridorParams``). Plain Python (no Amaranth import),
shared by the gateware, the Python models and the scenario files; validated on construction.
Distances in millimetres, angles in degrees clockwise from the sensor's forward (the
RPLIDAR's sense).
"""

from dataclasses import dataclass

from .errors import ParamError
from .params_base import ParamsBase

__all__ = ["CorridorParams", "NearestParams", "UartParams"]

_INT16_MAX = (1 << 15) - 1


@dataclass(frozen=True)
class NearestParams(ParamsBase):
    """Which samples ``NearestObstacle`` counts: a valid return (``distance_q2 > 0``) of at
    least ``min_quality`` and at least ``min_mm`` away (nearer ones are the robot itself)."""

    min_quality: int = 1
    min_mm: int = 0

    def __post_init__(self):
        self._check("min_quality", 0, 63)
        self._check("min_mm", 0, 16383)


@dataclass(frozen=True)
class CorridorParams(ParamsBase):
    """The corridor follower's control law (``hw/corridor_follow.py``), wheel speeds in DPS.

    Per revolution, with ``d`` the nearest distance and ``b`` its bearing (clockwise, 0 ahead):
    an obstacle nearer than ``stop_mm`` within ``front_deg`` of ahead turns the robot in place
    away from it (``(-turn, +turn)`` for the left); one nearer than ``keep_mm`` within
    ``side_deg`` of ahead steers away (``(base - steer, base + steer)`` to the left); otherwise
    straight ``(base, base)``. ``clockwise`` False reads the bearings counter-clockwise (a
    seeded bug: the robot steers towards the wall).
    """

    base_dps: int = 300
    steer_dps: int = 90
    turn_dps: int = 200
    keep_mm: int = 420
    stop_mm: int = 300
    front_deg: int = 30
    side_deg: int = 120
    clockwise: bool = True

    def __post_init__(self):
        self._check("base_dps", -_INT16_MAX, _INT16_MAX)
        self._check("steer_dps", 0, _INT16_MAX)
        self._check("turn_dps", 0, _INT16_MAX)
        self._check("keep_mm", 1, 16383)
        self._check("stop_mm", 1, 16383)
        self._check("front_deg", 1, 179)
        self._check("side_deg", 1, 179)
        if not isinstance(self.clockwise, bool):
            raise TypeError(f"clockwise must be True or False, not {self.clockwise!r}")
        if abs(self.base_dps) + self.steer_dps > _INT16_MAX:
            raise ParamError(
                f"base_dps +- steer_dps = {abs(self.base_dps) + self.steer_dps} does not fit a "
                f"signed 16-bit wheel command (max {_INT16_MAX})"
            )


@dataclass(frozen=True)
class UartParams(ParamsBase):
    """The serial receiver of ``CorridorFollowUart``: the design's clock and the LIDAR's baud
    rate (8N1). A bit lasts ``bit_cycles = round(clock_hz / baud)`` cycles; the receiver
    samples each bit in its middle counted from the start bit's fall, so the rounding may shift
    the stop bit's sample by at most 40% of a bit."""

    clock_hz: int = 50_000_000
    baud: int = 115_200

    def __post_init__(self):
        self._check("clock_hz", 1000, 1_000_000_000)
        self._check("baud", 300, 10_000_000)
        if self.bit_cycles < 4:
            raise ParamError(
                f"clock_hz={self.clock_hz} is too slow for baud={self.baud}: a bit must last at "
                f"least 4 cycles, it lasts {self.clock_hz / self.baud:.2f}"
            )
        drift = abs(self.bit_cycles * self.baud - self.clock_hz) / self.clock_hz * 9.5
        if drift > 0.4:
            raise ParamError(
                f"clock_hz={self.clock_hz} / baud={self.baud} = {self.clock_hz / self.baud:.2f} "
                f"cycles a bit, rounded to {self.bit_cycles}: the stop bit would be sampled "
                f"{drift:.0%} of a bit off its middle (at most 40%)"
            )

    @property
    def bit_cycles(self):
        return (self.clock_hz + self.baud // 2) // self.baud
