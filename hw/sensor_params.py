"""Elaboration parameters of the sensor designs: the HC-SR04 ultrasound driver
(``UltrasoundParams``), the obstacle interlock of ``FollowTargetSafe`` (``InterlockParams``)
and the KY-033 line follower (``FollowLineParams``).

Plain Python (no Amaranth import), like ``params.py``: the gateware, the Python models in
``sim/`` and the command line share these objects. Every value is validated on construction
with an error that says what is wrong. Times are given in microseconds and distances in
millimetres; the clock-cycle figures the gateware uses are derived properties, computed
with integer arithmetic so that the models and the gateware agree exactly.
"""

from dataclasses import dataclass

from .errors import ParamError
from .params_base import ParamsBase

__all__ = ["FOLLOW_LINE_PRESETS", "FollowLineParams", "InterlockParams", "UltrasoundParams"]

_INT16_MAX = (1 << 15) - 1
#: Width of the constant ``distance_k`` of the distance conversion (bits).
DISTANCE_K_BITS = 16
#: Width of the ``distance_mm`` output; ``DISTANCE_NONE`` is its value after a "no echo".
DISTANCE_BITS = 16
DISTANCE_NONE = (1 << DISTANCE_BITS) - 1


def _check_bool(name, value):
    if not isinstance(value, bool):
        raise TypeError(f"{name} must be True or False, not {type(value).__name__} {value!r}")


@dataclass(frozen=True)
class UltrasoundParams(ParamsBase):
    """Every elaboration-time parameter of ``UltrasoundDriver`` (HC-SR04).

    The defaults follow the HC-SR04 datasheet: a trigger pulse of at least 10 us (12 us
    here), one measurement every 60 ms, ranges up to 4 m. Echoes longer than the one of
    ``max_range_mm`` (such as the module's time-out pulse of about 38 ms) are "no echo".
    """

    #: The design's clock (Hz); every time below becomes a whole number of its cycles.
    clock_hz: int = 50_000_000
    #: Length of the TRIG pulse (us); the datasheet asks for at least 10 us.
    trigger_us: int = 12
    #: Time from one TRIG pulse to the next (us); the datasheet advises at least 60 ms.
    period_us: int = 60_000
    #: How long after TRIG falls the echo may start (us) before the measurement is "no echo".
    wait_us: int = 10_000
    #: The longest range measured (mm): a longer echo is "no echo".
    max_range_mm: int = 4000
    #: The speed of sound the design assumes, in mm/s (343 m/s: dry air at 20 degC).
    sound_mm_per_s: int = 343_000
    #: Width of the echo counter in bits; ``None``: ``full_echo_bits``, just wide enough for
    #: ``max_echo_cycles``. A narrower counter wraps (only for showing that bug,
    #: ``hw/variants.py``).
    echo_bits: int | None = None
    #: ECHO is high during the echo (the module's polarity); False inverts it (a seeded bug).
    echo_active_high: bool = True

    def __post_init__(self):
        self._check("clock_hz", 1000, 1_000_000_000)
        self._check("trigger_us", 10, 1_000_000)
        self._check("period_us", 1, 10_000_000)
        self._check("wait_us", 1, 10_000_000)
        self._check("max_range_mm", 1, DISTANCE_NONE - 1)
        self._check("sound_mm_per_s", 1000, 10_000_000)
        _check_bool("echo_active_high", self.echo_active_high)
        if self.trigger_cycles < 1 or self.wait_cycles < 2:
            raise ParamError(
                f"clock_hz={self.clock_hz} is too slow for trigger_us={self.trigger_us} and "
                f"wait_us={self.wait_us}: they must last at least 1 and 2 cycles"
            )
        if self.max_echo_cycles < 1:
            raise ParamError(
                f"max_range_mm={self.max_range_mm} is shorter than one clock "
                f"cycle of echo at clock_hz={self.clock_hz}"
            )
        if self.echo_bits is not None:
            self._check("echo_bits", 1, 64)
        # A measurement (echo start by the end of the wait, then at most max_echo_cycles of
        # echo) ends before the next trigger starts.
        needed = self.trigger_cycles + self.wait_cycles + self.max_echo_cycles + 2
        if self.period_cycles < needed:
            raise ParamError(
                f"period_us={self.period_us} is too short: a measurement takes up to "
                f"trigger_us + wait_us + the longest echo = {needed} cycles of "
                f"{self.period_cycles} (lengthen period_us or shorten wait_us/max_range_mm)"
            )
        if self.distance_k < 1:
            raise ParamError(f"clock_hz={self.clock_hz} is too fast for a distance constant")

    def _cycles(self, us):
        return us * self.clock_hz // 1_000_000

    @property
    def trigger_cycles(self):
        """TRIG stays high for this many cycles: ``trigger_us * clock_hz // 10**6``."""
        return self._cycles(self.trigger_us)

    @property
    def period_cycles(self):
        """Cycles from one TRIG rise to the next."""
        return self._cycles(self.period_us)

    @property
    def wait_cycles(self):
        """Edges after TRIG's fall at which the echo's start may be seen."""
        return self._cycles(self.wait_us)

    @property
    def max_echo_cycles(self):
        """The longest echo measured, in cycles: ``2 * max_range_mm / sound_mm_per_s`` s,
        rounded down. One cycle more is "no echo"."""
        return 2 * self.max_range_mm * self.clock_hz // self.sound_mm_per_s

    @property
    def full_echo_bits(self):
        """Bits the echo counter needs to count up to ``max_echo_cycles``."""
        return max(1, self.max_echo_cycles.bit_length())

    @property
    def counter_bits(self):
        """Width of the echo counter: ``echo_bits`` if given, else ``full_echo_bits``."""
        return self.full_echo_bits if self.echo_bits is None else self.echo_bits

    @property
    def distance_shift(self):
        """``S`` of ``distance_mm = (echo_cycles * distance_k) >> S``: the largest shift whose
        ``distance_k`` still fits 16 bits (the most precise constant of that width)."""
        shift = 0
        while self._k(shift + 1) < (1 << DISTANCE_K_BITS) and shift < 63:
            shift += 1
        return shift

    @property
    def distance_k(self):
        """``K``: millimetres per cycle of echo (half the round trip) times ``2**S``,
        rounded to the nearest integer."""
        return self._k(self.distance_shift)

    def _k(self, shift):
        # sound_mm_per_s / (2 * clock_hz) * 2**shift, rounded half up, in integers.
        return (self.sound_mm_per_s * (1 << shift) + self.clock_hz) // (2 * self.clock_hz)

    def distance_of(self, echo_cycles):
        """The distance (mm) the design reports for an echo of ``echo_cycles`` cycles (counted
        in a counter of ``counter_bits``, so that a narrow counter wraps here too)."""
        count = echo_cycles % (1 << self.counter_bits)
        return (count * self.distance_k) >> self.distance_shift


@dataclass(frozen=True)
class InterlockParams(ParamsBase):
    """Thresholds of the obstacle interlock of ``FollowTargetSafe`` (with hysteresis): a
    measurement nearer than ``stop_mm`` stops the wheels; one at ``resume_mm`` or farther, or
    no echo, releases them."""

    stop_mm: int = 300
    resume_mm: int = 400
    #: A measurement at ``resume_mm`` or farther releases the interlock, as does no echo.
    #: False: only a no-echo measurement that is also far does, which every no echo is and
    #: no real distance is (an AND where an OR belongs: a seeded bug, ``hw/variants.py``).
    release_on_far: bool = True

    def __post_init__(self):
        self._check("stop_mm", 1, DISTANCE_NONE - 1)
        self._check("resume_mm", 1, DISTANCE_NONE - 1)
        _check_bool("release_on_far", self.release_on_far)
        if self.resume_mm < self.stop_mm:
            raise ParamError(
                f"resume_mm={self.resume_mm} must be >= stop_mm={self.stop_mm} "
                "(no overlap of 'stop' and 'resume')"
            )


#: The choices of ``FollowLineParams.edge_side``.
EDGE_SIDES = ("left", "right")


@dataclass(frozen=True)
class FollowLineParams(ParamsBase):
    """Every elaboration-time parameter of ``FollowLine``.

    Wheel commands (DPS, ``left, right``) of the control law (``hw/follow_line.py``):
    straight ``(base, base)``; gentle turn left ``(base - gentle, base + gentle)``; sharp turn
    left ``(base - sharp, base + sharp)``; search left ``(-search, +search)`` (turning in
    place); the right turns mirrored. At the defaults a GoPiGo3 (wheels 66.5 mm, base 117 mm)
    drives at 0.145 m/s; the gentle turn's radius is 0.146 m and the sharp one's 0.059 m
    (radius = base / 2 * (right + left) / (right - left)), both tighter than the track's
    tightest curve (0.3 m).
    """

    #: Line sensors, 1..3, bit i of ``line`` = sensor i from the robot's left to its right.
    n_sensors: int = 3
    base_dps: int = 250
    gentle_turn_dps: int = 100
    sharp_turn_dps: int = 250
    search_dps: int = 150
    #: The KY-033's digital output is high over a dark line (no infrared reflected); False
    #: reads it the other way round (a seeded bug, ``inverted_polarity``).
    active_high: bool = True
    #: One sensor: the edge of the line it follows ("left": the line lies to its right).
    edge_side: str = "left"

    def __post_init__(self):
        self._check("n_sensors", 1, 3)
        self._check("base_dps", -_INT16_MAX, _INT16_MAX)
        self._check("gentle_turn_dps", 0, _INT16_MAX)
        self._check("sharp_turn_dps", 0, _INT16_MAX)
        self._check("search_dps", -_INT16_MAX, _INT16_MAX)
        _check_bool("active_high", self.active_high)
        if not isinstance(self.edge_side, str) or self.edge_side not in EDGE_SIDES:
            raise ParamError(
                f"edge_side must be one of {', '.join(EDGE_SIDES)}; got {self.edge_side!r}"
            )
        for name in ("gentle_turn_dps", "sharp_turn_dps"):
            turn = getattr(self, name)
            if abs(self.base_dps) + turn > _INT16_MAX:
                raise ParamError(
                    f"base_dps +- {name} = {abs(self.base_dps) + turn} does not "
                    f"fit a signed 16-bit wheel command (max {_INT16_MAX})"
                )

    @classmethod
    def preset(cls, name, **changes):
        """Preset ``name`` (``FOLLOW_LINE_PRESETS``) with ``changes`` on top."""
        if name not in FOLLOW_LINE_PRESETS:
            raise ParamError(
                f"unknown follow_line preset {name!r}; known presets: "
                f"{', '.join(FOLLOW_LINE_PRESETS)}"
            )
        return cls(**{**FOLLOW_LINE_PRESETS[name][1], **changes})

    @classmethod
    def inverted_polarity(cls, **changes):
        """The seeded bug: the sensors' output read with the wrong polarity."""
        return cls.preset("inverted_polarity", **changes)


#: name -> (description, FollowLineParams values).
FOLLOW_LINE_PRESETS = {
    "default": ("this project's line follower", {}),
    "inverted_polarity": (
        "seeded bug: reads the KY-033 output as low over the line",
        {"active_high": False},
    ),
}
