"""Elaboration parameters of ``FollowTarget``, with the hardware contract's defaults.

One frozen dataclass is shared by the gateware, the numpy golden model and every simulation
backend, so that "the same parameters" means the same object everywhere. The defaults are this
project's own design at 160x120 (docs/contract.md); count thresholds scale with the frame area
(see ``area_scale``). The published FPGA-Robotics design differs in its found rule, proximity
thresholds, bin groups, motor law and saturation: it is the preset
``FollowTargetParams.published()`` (docs/published.md compares the two, value by value).
Every value is validated on construction with an error that says what is wrong.
"""

from dataclasses import dataclass, field, fields

from .errors import ParamError
from .validate import check_int

__all__ = [
    "DEFAULT_BASE_DPS",
    "DEFAULT_PROXIMITY_THRESHOLDS",
    "DEFAULT_STEER_DPS",
    "PRESETS",
    "FollowTargetParams",
    "preset_values",
]

#: Proximity thresholds at 160x120 (pixels in the window); scaled by ``area_scale``.
DEFAULT_PROXIMITY_THRESHOLDS = (128, 256, 512, 1024, 2048, 4096, 6144)
#: Base wheel speed (DPS) for each proximity level 0..7.
DEFAULT_BASE_DPS = (0, 400, 300, 200, 150, 100, -100, -150)
#: ``min_pixels`` at 160x120; scaled by ``area_scale``.
DEFAULT_MIN_PIXELS = 128
#: Table motor law: how much slower the slow wheel turns, by the distance of the LED from the
#: centre (LEDs 3/4, 2/5, 1/6, 0/7). Only read when ``motor_law = "table"``.
DEFAULT_STEER_DPS = (125, 175, 225, 275)

#: The choices of the parameters that are words; the first is the default.
CHOICES = {
    "found_rule": ("ge", "gt"),
    "motor_law": ("p_control", "table"),
    "lost_motion": ("hold", "drive"),
    "search_side_from": ("centroid", "leds"),
    "centred_search_side": ("right", "left"),
}

#: The published FPGA-Robotics design at 160x120, as values of this design's parameters
#: (docs/published.md: what each one is and why the defaults differ). Its colour filter,
#: margins, ``lost_frames`` and ``search_dps`` are the defaults already.
_PUBLISHED = {
    "min_pixels": 128,
    "found_rule": "gt",
    # Levels 1 and 2 never occur: the published 128 / 768 / 1792 branches all give 3.
    "proximity_thresholds": (128, 128, 128, 3072, 3840, 4096, 6144),
    "group_column_offset": 1,
    "motor_law": "table",
    "base_dps": (600, 550, 450, 350, 250, 150, -250, -450),
    "steer_dps": (125, 175, 225, 275),
    "lost_motion": "drive",
    "search_side_from": "leds",
    "centred_search_side": "right",
    # No saturation: no value of the table reaches it.
    "max_dps": (1 << 15) - 1,
    "lost_frames": 15,
    "search_dps": 250,
}
#: Counts of ``_PUBLISHED`` given at 160x120, scaled by ``area_scale`` at other sizes.
_SCALED = ("min_pixels", "proximity_thresholds")

#: Known presets: name → what it is.
PRESETS = {
    "published": "the published FPGA-Robotics design (docs/published.md)",
}


def preset_values(name, width=160, height=120):
    """The parameter values of preset ``name`` for a ``width`` x ``height`` design: a dict of
    ``FollowTargetParams`` fields (counts scaled by ``area_scale``). An unknown name raises
    ``ValueError`` listing the known ones."""
    if name not in PRESETS:
        raise ParamError(f"unknown design preset {name!r}; known presets: {', '.join(PRESETS)}")
    scale = max(1, (width * height) // (160 * 120))
    values = dict(_PUBLISHED)
    values["min_pixels"] *= scale
    values["proximity_thresholds"] = tuple(t * scale for t in values["proximity_thresholds"])
    return values


_INT16_MIN, _INT16_MAX = -(1 << 15), (1 << 15) - 1


@dataclass(frozen=True)
class FollowTargetParams:
    """Every elaboration-time parameter of ``FollowTarget``.

    Parameters left as ``None`` take the hardware contract's default for the geometry:
    ``margin_x = width // 10``, ``margin_y = height // 15``, and ``min_pixels`` and
    ``proximity_thresholds`` are the 160x120 values multiplied by ``area_scale``.

    ``area_scale`` is ``(width * height) // (160 * 120)``, clamped to at least 1 so that
    geometries smaller than 160x120 (used by fast tests) keep the 160x120 thresholds
    rather than thresholds of zero. This clamp is our choice where the contract is silent.
    """

    width: int = 160
    height: int = 120
    diff_min: int = 6
    similar_max: int = 2
    white_min: int = 12
    margin_x: int | None = None
    margin_y: int | None = None
    min_pixels: int | None = None
    proximity_thresholds: tuple | None = None
    base_dps: tuple = DEFAULT_BASE_DPS
    kp_num: int = 3
    kp_shift: int = 0
    max_dps: int = 512
    lost_frames: int = 15
    search_dps: int = 250
    #: ``found`` is ``N >= min_pixels`` ("ge") or ``N > min_pixels`` ("gt", published).
    found_rule: str = "ge"
    #: 0: the left/right halves and the 2- and 3-bin sums of the LED code use the bins as they
    #: are; 1: each column counts in the group of the column after it, the window's last column
    #: in the first group (the published one-column lag; ``h0``, ``h7`` and ``N`` unchanged).
    group_column_offset: int = 0
    #: "p_control": ``base_dps[proximity] +- turn``, ``turn`` from the centroid (the defaults);
    #: "table": ``base_dps[proximity]`` on the fast wheel, the slow wheel ``steer_dps`` slower
    #: by the LED's distance from the centre, turning to the LED's side (published).
    motor_law: str = "p_control"
    steer_dps: tuple = DEFAULT_STEER_DPS
    #: Lost frames before the search: "hold" the last command, or "drive" on at
    #: ``base_dps[proximity]`` of the frame, steered by the last LED code (published; "drive"
    #: needs ``motor_law = "table"``).
    lost_motion: str = "hold"
    #: Side of the last sighting, which the search turns to: the sign of ``centroid_x -
    #: width // 2`` ("centroid"), or the LED code's half ("leds", published), where the centred
    #: code counts as ``centred_search_side``.
    search_side_from: str = "centroid"
    centred_search_side: str = "right"
    #: Width of the column-sum register ``SX`` (``None``: ``full_sum_x_bits``, wide enough for
    #: any frame). A narrower ``SX`` wraps (``SX mod 2**sx_bits``) in the gateware and the
    #: model alike, and the centroid ``SX // N`` comes out off-centre: the paper's story (d),
    #: a signal with too narrow a bit range (docs/stories.md). Only for showing that bug.
    sx_bits: int | None = None

    # Derived, filled in by __post_init__.
    area_scale: int = field(init=False)

    def __post_init__(self):
        self._check("width", 16, 4096)
        self._check("height", 2, 4096)
        scale = max(1, (self.width * self.height) // (160 * 120))
        object.__setattr__(self, "area_scale", scale)
        if self.margin_x is None:
            object.__setattr__(self, "margin_x", self.width // 10)
        if self.margin_y is None:
            object.__setattr__(self, "margin_y", self.height // 15)
        if self.min_pixels is None:
            object.__setattr__(self, "min_pixels", DEFAULT_MIN_PIXELS * scale)
        if self.proximity_thresholds is None:
            object.__setattr__(
                self, "proximity_thresholds", tuple(t * scale for t in DEFAULT_PROXIMITY_THRESHOLDS)
            )
        object.__setattr__(self, "proximity_thresholds", tuple(self.proximity_thresholds))
        object.__setattr__(self, "base_dps", tuple(self.base_dps))
        object.__setattr__(self, "steer_dps", tuple(self.steer_dps))
        self._validate()

    @classmethod
    def published(cls, **changes):
        """The published FPGA-Robotics design as this design's parameters (160x120 unless
        ``width``/``height`` are given; its pixel counts then scale by ``area_scale``), with
        ``changes`` on top. See docs/published.md."""
        return cls.preset("published", **changes)

    @classmethod
    def preset(cls, name, **changes):
        """Preset ``name`` (``PRESETS``) with ``changes`` on top; an unknown name is a
        ``ValueError`` listing the known presets."""
        values = preset_values(name, changes.get("width", 160), changes.get("height", 120))
        values.update(changes)
        return cls(**values)

    def _check(self, name, lo=None, hi=None):
        """``check_int`` of one field; the field keeps the plain ``int`` it returns."""
        object.__setattr__(self, name, check_int(name, getattr(self, name), lo, hi))

    def _check_choice(self, name):
        value, choices = getattr(self, name), CHOICES[name]
        if not isinstance(value, str):
            raise TypeError(
                f"{name} must be a string, one of {', '.join(choices)}; "
                f"got {type(value).__name__} {value!r}"
            )
        if value not in choices:
            raise ParamError(f"{name} must be one of {', '.join(choices)}; got {value!r}")

    def _check_each(self, name, lo, hi):
        values = getattr(self, name)
        object.__setattr__(
            self, name, tuple(check_int(f"{name}[{i}]", v, lo, hi) for i, v in enumerate(values))
        )

    def _validate(self):
        for name in ("diff_min", "similar_max", "white_min"):
            self._check(name, 0, 15)
        self._check("margin_x", 0)
        self._check("margin_y", 0)
        if self.window_width <= 0:
            raise ParamError(
                f"margin_x={self.margin_x} leaves no window in a frame {self.width} wide"
            )
        if self.window_height <= 0:
            raise ParamError(
                f"margin_y={self.margin_y} leaves no window in a frame {self.height} high"
            )
        if self.window_width % 8:
            raise ParamError(
                f"the window width (width - 2*margin_x = {self.window_width}) must be divisible "
                f"by 8 so that the 8 bins are equal; adjust width or margin_x"
            )
        # A threshold above the window's pixel count is allowed: that level never occurs.
        max_count = (1 << 32) - 1
        self._check("min_pixels", 1, max_count)
        if len(self.proximity_thresholds) != 7:
            raise ParamError(
                f"proximity_thresholds needs 7 values (levels 1..7), got "
                f"{len(self.proximity_thresholds)}"
            )
        self._check_each("proximity_thresholds", 0, max_count)
        if list(self.proximity_thresholds) != sorted(self.proximity_thresholds):
            raise ParamError(
                f"proximity_thresholds must be non-decreasing, got {self.proximity_thresholds}"
            )
        if len(self.base_dps) != 8:
            raise ParamError(
                f"base_dps needs 8 values (one per proximity level 0..7), got {len(self.base_dps)}"
            )
        self._check_each("base_dps", _INT16_MIN, _INT16_MAX)
        self._check("kp_num", _INT16_MIN, _INT16_MAX)
        self._check("kp_shift", 0, 15)
        self._check("max_dps", 0, _INT16_MAX)
        self._check("lost_frames", 1, (1 << 16) - 1)
        # -32768 is excluded: searching the other way negates it, which would wrap in 16 bits.
        self._check("search_dps", -_INT16_MAX, _INT16_MAX)
        for name in CHOICES:
            self._check_choice(name)
        self._check("group_column_offset", 0, 1)
        if self.sx_bits is not None:
            self._check("sx_bits", 1, self.full_sum_x_bits)
        if len(self.steer_dps) != 4:
            raise ParamError(
                f"steer_dps needs 4 values (LED distance 0..3 from the centre), got "
                f"{len(self.steer_dps)}"
            )
        # Non-negative: the slow wheel moves towards 0 and the result fits 16 bits.
        self._check_each("steer_dps", 0, _INT16_MAX)
        if self.lost_motion == "drive" and self.motor_law != "table":
            raise ParamError(
                "lost_motion='drive' needs motor_law='table' (it drives on with the table's "
                f"speed and the last LED code), got motor_law={self.motor_law!r}"
            )

    @property
    def motor_uses_leds(self):
        """Whether the motor controller reads the LED code (the table law, or the search side
        from the LEDs)."""
        return self.motor_law == "table" or self.search_side_from == "leds"

    # Window geometry -------------------------------------------------------------------------

    @property
    def window_width(self):
        return self.width - 2 * self.margin_x

    @property
    def window_height(self):
        return self.height - 2 * self.margin_y

    @property
    def window_pixels(self):
        return self.window_width * self.window_height

    @property
    def bin_width(self):
        return self.window_width // 8

    @property
    def pixels_per_frame(self):
        return self.width * self.height

    # Derived widths --------------------------------------------------------------------------

    @property
    def x_bits(self):
        """Bits of a column index, and of ``centroid_x``: enough for ``width - 1``."""
        return max(1, (self.width - 1).bit_length())

    @property
    def y_bits(self):
        return max(1, (self.height - 1).bit_length())

    @property
    def count_bits(self):
        """Bits of the pixel count ``N`` (and of each bin count)."""
        return max(1, self.window_pixels.bit_length())

    @property
    def full_sum_x_bits(self):
        """Bits ``SX`` needs to hold the sum of the column index of every pixel of a window
        that matches everywhere: its width unless ``sx_bits`` narrows it."""
        return max(1, (self.window_pixels * (self.width - 1)).bit_length())

    @property
    def sum_x_bits(self):
        """Bits of ``SX``, the sum of the column index of every counted pixel:
        ``full_sum_x_bits``, or ``sx_bits`` when given (then ``SX`` wraps modulo
        ``2**sx_bits``)."""
        return self.full_sum_x_bits if self.sx_bits is None else self.sx_bits

    # Latencies of the gateware, in clock cycles (see docs/hardware.md) ------------------------

    @property
    def filter_latency(self):
        """A pixel sampled on ``pixels`` at edge k is sampled on ``filtered`` at edge
        k + filter_latency (one register after the colour comparison)."""
        return 1

    @property
    def divider_cycles(self):
        """Steps of the sequential divider computing ``centroid_x``: one per quotient bit,
        ``x_bits + 1`` (one bit more than ``width - 1`` needs, always 0: it stands in for a
        delay register before the outputs)."""
        return self.x_bits + 1

    @property
    def result_latency(self):
        """The frame's last pixel sampled at edge P: ``frame_done`` and the per-frame outputs
        show the new values right after edge P + result_latency.

        The colour filter loads the last pixel at edge P itself; then the window counter (1),
        the divider start (1), the divider steps (``divider_cycles``) and the output load (1):
        ``x_bits + 4`` (the edge-by-edge table is in docs/hardware.md).
        """
        return self.x_bits + 4

    @property
    def motor_latency(self):
        """Motor outputs show the new frame's values right after edge
        P + result_latency + motor_latency: one register after ``frame_done``."""
        return 1

    def replace(self, **changes):
        """A copy with some parameters changed; derived defaults are recomputed."""
        values = {f.name: getattr(self, f.name) for f in fields(self) if f.init}
        # Values that were derived from the geometry follow a geometry change.
        if "width" in changes or "height" in changes:
            for name in ("margin_x", "margin_y", "min_pixels", "proximity_thresholds"):
                values.pop(name)
        values.update(changes)
        return FollowTargetParams(**values)

    def as_dict(self):
        return {f.name: getattr(self, f.name) for f in fields(self) if f.init}
