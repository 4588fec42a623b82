"""Elaboration parameters of ``FollowTarget``, with the hardware contract's defaults.

One frozen dataclass is shared by the gateware, the numpy golden model and every simulation
backend, so that "the same parameters" means the same object everywhere. Defaults are the
published values at 160x120; count thresholds scale with the frame area (see ``area_scale``).
Every value is validated on construction with an error that says what is wrong.
"""

from dataclasses import dataclass, field, fields

from .validate import check_int

__all__ = ["DEFAULT_BASE_DPS", "DEFAULT_PROXIMITY_THRESHOLDS", "FollowTargetParams"]

#: Proximity thresholds at 160x120 (pixels in the window); scaled by ``area_scale``.
DEFAULT_PROXIMITY_THRESHOLDS = (128, 256, 512, 1024, 2048, 4096, 6144)
#: Base wheel speed (DPS) for each proximity level 0..7.
DEFAULT_BASE_DPS = (0, 400, 300, 200, 150, 100, -100, -150)
#: ``min_pixels`` at 160x120; scaled by ``area_scale``.
DEFAULT_MIN_PIXELS = 128

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
        self._validate()

    def _check(self, name, lo=None, hi=None):
        """``check_int`` of one field; the field keeps the plain ``int`` it returns."""
        object.__setattr__(self, name, check_int(name, getattr(self, name), lo, hi))

    def _check_each(self, name, lo, hi):
        values = getattr(self, name)
        object.__setattr__(self, name, tuple(
            check_int(f"{name}[{i}]", v, lo, hi) for i, v in enumerate(values)
        ))

    def _validate(self):
        for name in ("diff_min", "similar_max", "white_min"):
            self._check(name, 0, 15)
        self._check("margin_x", 0)
        self._check("margin_y", 0)
        if self.window_width <= 0:
            raise ValueError(
                f"margin_x={self.margin_x} leaves no window in a frame {self.width} wide"
            )
        if self.window_height <= 0:
            raise ValueError(
                f"margin_y={self.margin_y} leaves no window in a frame {self.height} high"
            )
        if self.window_width % 8:
            raise ValueError(
                f"the window width (width - 2*margin_x = {self.window_width}) must be divisible "
                f"by 8 so that the 8 bins are equal; adjust width or margin_x"
            )
        # A threshold above the window's pixel count is allowed: that level never occurs.
        max_count = (1 << 32) - 1
        self._check("min_pixels", 1, max_count)
        if len(self.proximity_thresholds) != 7:
            raise ValueError(
                f"proximity_thresholds needs 7 values (levels 1..7), got "
                f"{len(self.proximity_thresholds)}"
            )
        self._check_each("proximity_thresholds", 0, max_count)
        if list(self.proximity_thresholds) != sorted(self.proximity_thresholds):
            raise ValueError(
                f"proximity_thresholds must be non-decreasing, got {self.proximity_thresholds}"
            )
        if len(self.base_dps) != 8:
            raise ValueError(
                f"base_dps needs 8 values (one per proximity level 0..7), got {len(self.base_dps)}"
            )
        self._check_each("base_dps", _INT16_MIN, _INT16_MAX)
        self._check("kp_num", _INT16_MIN, _INT16_MAX)
        self._check("kp_shift", 0, 15)
        self._check("max_dps", 0, _INT16_MAX)
        self._check("lost_frames", 1, (1 << 16) - 1)
        # -32768 is excluded: searching the other way negates it, which would wrap in 16 bits.
        self._check("search_dps", -_INT16_MAX, _INT16_MAX)

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
    def sum_x_bits(self):
        """Bits of ``SX``, the sum of the column index of every counted pixel."""
        return max(1, (self.window_pixels * (self.width - 1)).bit_length())

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
