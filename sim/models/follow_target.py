"""Golden model of ``FollowTarget`` in numpy, written from docs/contract.md (not from the RTL).

Reading of the contract where it leaves room (the gateware must agree):

- Lost counter: on every frame without the target the counter of consecutive lost frames is
  incremented *before* the decision, and the design searches as soon as the count is
  ``>= lost_frames``. So the frame on which the count *reaches* ``lost_frames`` already searches:
  with ``lost_frames = 15`` lost frames 1..14 hold the last command and the 15th consecutive lost
  frame is the first that searches; with ``lost_frames = 1`` the first lost frame searches. A
  found frame sets the counter back to 0. The counter saturates at ``lost_frames`` (its value
  beyond that never changes an output).
- Holding "the last command" means the motor outputs keep whatever they showed (a tracking
  command, a search command, or 0 after reset). ``last_side`` changes only on found frames;
  after reset it is "left", so a design that never saw the target searches to the left
  (``left = -search_dps, right = +search_dps``).
- Search speeds are ``+-search_dps`` exactly (no saturation to ``max_dps``), as written, taken
  as 16-bit two's complement like every motor output: only ``search_dps = -32768`` is affected
  (its negation wraps to -32768).
- ``found`` (``N >= min_pixels``) and ``proximity`` are independent: a found frame with
  proximity 0 (possible only when ``min_pixels`` is below the first threshold) uses
  ``base_dps[0]``.
- ``turn = (kp_num * e) >> kp_shift`` is a floor division by ``2**kp_shift`` (rounds towards
  minus infinity for negative ``e``), then ``base +- turn`` saturate to ``[-max_dps, max_dps]``.

The knobs that express the published design (``FollowTargetParams.published()``,
docs/published.md) are written here from their definitions: ``found_rule``,
``group_column_offset`` (each window column grouped with the column after it, the last with
the first), ``motor_law = "table"`` (``table_command``), ``lost_motion = "drive"`` and the
search side from the LED code.

Everything is vectorised per frame: the colour filter is one lookup in a 4096-entry table per
colour (built from the contract's formulas), the tracker a few numpy reductions.
"""

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.pixel import color_select_value

from ..camera.frames import FrameError, to_rgb444, unpack_rgb444

__all__ = [
    "FollowTargetModel",
    "ModelFrame",
    "MotorModel",
    "TrackerResult",
    "centroid_leds",
    "color_match",
    "filter_frame",
    "is_found",
    "match_table",
    "proximity_level",
    "table_command",
    "track_frame",
]

#: ``centroid_leds`` when the target is centred (LEDs 3 and 4).
LEDS_CENTRED = 0b0001_1000


def _match_formula(r, g, b, color_sel, diff_min, similar_max, white_min):
    """The contract's colour table on signed int arrays ``r, g, b`` (0..15)."""
    d, s = diff_min, similar_max
    if color_sel == 0b000:
        return np.ones(np.shape(r), bool)
    if color_sel == 0b100:
        return r - np.maximum(g, b) >= d
    if color_sel == 0b010:
        return g - np.maximum(r, b) >= d
    if color_sel == 0b001:
        return b - np.maximum(r, g) >= d
    if color_sel == 0b110:
        return (np.abs(r - g) <= s) & (np.minimum(r, g) - b >= d)
    if color_sel == 0b101:
        return (np.abs(r - b) <= s) & (np.minimum(r, b) - g >= d)
    if color_sel == 0b011:
        return (np.abs(g - b) <= s) & (np.minimum(g, b) - r >= d)
    # 0b111, white
    hi = np.maximum(np.maximum(r, g), b)
    lo = np.minimum(np.minimum(r, g), b)
    return (hi - lo <= s) & (lo >= white_min)


@lru_cache(maxsize=64)
def _cached_table(color_sel, diff_min, similar_max, white_min):
    r, g, b = unpack_rgb444(np.arange(4096))
    table = _match_formula(r, g, b, color_sel, diff_min, similar_max, white_min)
    table.flags.writeable = False
    return table


def match_table(color_sel, params):
    """Read-only bool array of 4096 entries: does packed pixel ``p`` match ``color_sel``?"""
    sel = color_select_value(color_sel)
    return _cached_table(sel, params.diff_min, params.similar_max, params.white_min)


def _check_packed(packed, params):
    if not isinstance(packed, np.ndarray) or packed.ndim != 2 or packed.dtype.kind != "u":
        raise FrameError(
            "the model takes a packed RGB444 frame: an (H, W) numpy array of unsigned ints "
            "(convert RGB888 with fpga_robotics.sim.camera.frames.to_rgb444)"
        )
    if packed.shape != (params.height, params.width):
        raise FrameError(
            f"a packed RGB444 frame must have shape ({params.height}, {params.width}) for a "
            f"{params.width}x{params.height} design, got {packed.shape}"
        )


def color_match(packed, color_sel, params):
    """Bool (H, W): which pixels of a packed RGB444 frame match colour ``color_sel``."""
    _check_packed(packed, params)
    return match_table(color_sel, params)[packed]


def filter_frame(packed, color_sel, params):
    """The filtered frame, uint16 (H, W): the pixel where it matches, else 0."""
    match = color_match(packed, color_sel, params)
    return np.where(match, packed, np.uint16(0)).astype(np.uint16, copy=False)


@dataclass(frozen=True)
class TrackerResult:
    """Per-frame tracker outputs and the counts they come from.

    Attributes
    ----------
    found, proximity, centroid_x, centroid_leds
        The design's outputs.
    count
        ``N``: matching pixels in the window.
    bins
        ``(h0, ..., h7)``: matching pixels per bin of window columns, left to right.
    sum_x
        ``SX``: sum of the frame column index of every counted pixel, modulo
        ``2**params.sx_bits`` when ``sx_bits`` narrows it.
    """

    found: bool
    proximity: int
    centroid_x: int
    centroid_leds: int
    count: int
    bins: tuple
    sum_x: int

    @property
    def left_count(self):
        """``L = h0 + h1 + h2 + h3``."""
        return sum(self.bins[:4])

    @property
    def right_count(self):
        """``R = h4 + h5 + h6 + h7``."""
        return sum(self.bins[4:])


def proximity_level(count, thresholds):
    """How many thresholds satisfy ``count >= t`` (0..7)."""
    return sum(1 for t in thresholds if count >= t)


def is_found(count, params):
    """``found`` for ``N = count`` under ``params.found_rule``."""
    if params.found_rule == "gt":
        return count > params.min_pixels
    return count >= params.min_pixels


def centroid_leds(bins, count, found, groups=None):
    """The LED code (bit 0 = leftmost LED) from the bins and ``N``.

    ``groups`` (default: ``bins``) are the eight counts the halves ``L``, ``R`` and the 2-
    and 3-bin sums are taken from; the single outermost bins are always ``bins[0]`` and
    ``bins[7]`` (with ``group_column_offset = 1`` the groups are the bins shifted by a column).
    """
    if not found:
        return 0
    groups = bins if groups is None else groups
    left, right = sum(groups[:4]), sum(groups[4:])
    half = count >> 1
    if abs(left - right) < (count >> 4):
        return LEDS_CENTRED
    if left > right:
        sums = (bins[0], sum(groups[0:2]), sum(groups[0:3]))
        leds = (0, 1, 2, 3)
    else:
        sums = (bins[7], sum(groups[6:8]), sum(groups[5:8]))
        leds = (7, 6, 5, 4)
    for led, s in zip(leds, sums):
        if s >= half:
            return 1 << led
    return 1 << leds[3]


def track_frame(match, params):
    """Tracker outputs of one frame from its (H, W) bool match mask."""
    if match.shape != (params.height, params.width):
        raise FrameError(
            f"the match mask must have shape ({params.height}, {params.width}), got {match.shape}"
        )
    mx, my = params.margin_x, params.margin_y
    window = match[my : params.height - my, mx : params.width - mx]
    columns = np.count_nonzero(window, axis=0)
    bins = tuple(int(v) for v in columns.reshape(8, params.bin_width).sum(axis=1))
    groups = None
    if params.group_column_offset:
        # Each column in the group of the column after it; the last column in the first.
        shifted = np.roll(columns, params.group_column_offset)
        groups = tuple(int(v) for v in shifted.reshape(8, params.bin_width).sum(axis=1))
    count = sum(bins)
    sum_x = int(columns @ np.arange(mx, params.width - mx))
    if params.sx_bits is not None:  # a too-narrow SX register wraps (docs/stories.md, (d))
        sum_x %= 1 << params.sx_bits
    found = is_found(count, params)
    return TrackerResult(
        found=found,
        proximity=proximity_level(count, params.proximity_thresholds),
        centroid_x=sum_x // count if found else 0,
        centroid_leds=centroid_leds(bins, count, found, groups),
        count=count,
        bins=bins,
        sum_x=sum_x,
    )


def _wrap16(v):
    """``v`` as a signed 16-bit register holds it."""
    return ((v + (1 << 15)) & 0xFFFF) - (1 << 15)


def _led_distance(code):
    """Distance from the centre (0..3) of the outermost LED lit in ``code``."""
    for distance in (3, 2, 1):
        if code & ((1 << (3 - distance)) | (1 << (4 + distance))):
            return distance
    return 0


def table_command(speed, code, params):
    """The table motor law's ``(left, right)`` for a speed (``base_dps[proximity]``) and an LED
    code, before saturation.

    No LED code (0: the target never seen): both 0. Centred (LEDs 3 and 4): both ``speed``.
    Otherwise the robot turns to the code's side (left when any of LEDs 0..3 is lit): one wheel
    keeps ``speed`` and the other moves ``steer_dps[d]`` towards 0 (``d``: the outermost lit
    LED's distance from the centre). Forwards (``speed >= 0``) that is the wheel on the
    target's side; backwards, the other one.
    """
    if code == 0:
        return 0, 0
    if code & LEDS_CENTRED == LEDS_CENTRED:
        return speed, speed
    d = params.steer_dps[_led_distance(code)]
    slow = speed + d if speed < 0 else speed - d
    target_left = bool(code & 0x0F)
    if target_left == (speed >= 0):
        return slow, speed
    return speed, slow


class MotorModel:
    """The per-frame motor controller, with its state across frames.

    Parameters
    ----------
    params : FollowTargetParams

    Attributes
    ----------
    left, right : int
        Current motor outputs (signed DPS); 0 after reset.
    lost_count : int
        Consecutive frames without the target (saturates at ``lost_frames``).
    last_side : str
        ``"left"`` or ``"right"``: side of the last seen target; ``"left"`` after reset.
    last_leds : int
        LED code of the last frame with the target (0 after reset); the table law steers by it
        while the target is lost.
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError("params must be a FollowTargetParams")
        self.params = params
        self.reset()

    def reset(self):
        self.left = 0
        self.right = 0
        self.lost_count = 0
        self.last_side = "left"
        self.last_leds = 0

    def _saturate(self, v):
        m = self.params.max_dps
        return max(-m, min(m, v))

    @property
    def searching(self):
        """True while the outputs are the search command (lost for ``lost_frames`` or more)."""
        return self.lost_count >= self.params.lost_frames

    def step(self, tracker):
        """Update on one frame's ``TrackerResult``; return ``(left, right)``."""
        p = self.params
        base = p.base_dps[tracker.proximity]
        if tracker.found:
            self.lost_count = 0
            e = tracker.centroid_x - p.width // 2
            if p.motor_law == "table":
                left, right = table_command(base, tracker.centroid_leds, p)
            else:
                turn = (p.kp_num * e) >> p.kp_shift  # Python's >> on ints is arithmetic
                left, right = base + turn, base - turn
            self.left, self.right = self._saturate(left), self._saturate(right)
            self.last_side = self._side(e, tracker.centroid_leds)
            self.last_leds = tracker.centroid_leds
        else:
            self.lost_count = min(self.lost_count + 1, p.lost_frames)
            if self.searching:
                s = p.search_dps if self.last_side == "right" else -p.search_dps
                self.left, self.right = _wrap16(s), _wrap16(-s)
            elif p.lost_motion == "drive":
                # On at this frame's speed, steered by the last sighting.
                left, right = table_command(base, self.last_leds, p)
                self.left, self.right = self._saturate(left), self._saturate(right)
            # else: hold the last command
        return self.left, self.right

    def _side(self, e, code):
        """Side of a sighting: the sign of ``e``, or the LED code's half."""
        p = self.params
        if p.search_side_from == "centroid":
            return "right" if e >= 0 else "left"
        if code & LEDS_CENTRED == LEDS_CENTRED:
            return p.centred_search_side
        return "right" if code & 0xF0 else "left"


@dataclass(frozen=True, eq=False)
class ModelFrame:
    """What the model produced for one frame."""

    filtered: np.ndarray
    tracker: TrackerResult
    motor_left: int
    motor_right: int


class FollowTargetModel:
    """The whole design, frame by frame: filter, tracker and motor controller with state.

    Parameters
    ----------
    params : FollowTargetParams, optional
        Defaults to ``FollowTargetParams()``.
    """

    def __init__(self, params=None):
        self.params = params if params is not None else FollowTargetParams()
        self.motor = MotorModel(self.params)

    def reset(self):
        """Back to the power-on state (motor outputs 0, last side left, lost count 0)."""
        self.motor.reset()

    def process(self, packed, color_sel):
        """Process one frame (packed RGB444 (H, W), or RGB888 (H, W, 3)); return a ModelFrame."""
        p = self.params
        packed = to_rgb444(packed, p.width, p.height)
        match = match_table(color_sel, p)[packed]
        filtered = np.where(match, packed, np.uint16(0)).astype(np.uint16, copy=False)
        tracker = track_frame(match, p)
        left, right = self.motor.step(tracker)
        return ModelFrame(filtered, tracker, left, right)
