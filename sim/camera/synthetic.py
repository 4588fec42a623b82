"""Seeded synthetic camera frames for tests and benchmarks of every backend.

Frames are RGB888 images (height, width, 3) of uint8, like a host camera frame; pass them to a
backend as they are, or pack them with :func:`as_rgb444` (``fpga_robotics.sim.camera.frames.to_rgb444``).
Every random choice comes from the ``rng`` argument: ``None`` means seed 0, an int is a seed, a
``numpy.random.Generator`` is used as it is. The same arguments always give the same pixels.

Colours are chosen so that, at the default thresholds (``diff_min=6``, ``similar_max=2``,
``white_min=12``), a target blob matches the filter of its colour at every pixel, even with its
colour jitter, and the backgrounds ``"noise"``, ``"dark"``, ``"black"`` and ``"grey"`` match none
of the seven colours anywhere. ``"random"`` backgrounds and ``speckle`` add pixels that may match.
The ``"wood"`` distractor is the red-brown of a wooden divider: RGB444 (9, 4, 2), so
``r - max(g, b) = 5``: not red at ``diff_min=6``, red at ``diff_min=5``.
"""

from dataclasses import dataclass

import numpy as np

from fpga_robotics.hw.validate import check_int

from .frames import to_rgb444

__all__ = [
    "BACKGROUNDS",
    "DISTRACTOR_RGB",
    "SCENARIOS",
    "TARGET_RGB",
    "Blob",
    "Scenario",
    "TargetState",
    "as_rgb444",
    "background_frame",
    "blob_frame",
    "draw_blobs",
    "empty_frame",
    "make_rng",
    "random_frame",
    "scenario",
    "sequence",
]

#: Saturated RGB888 colour of a target of each filter colour (RGB444: 15 and 2).
TARGET_RGB = {
    "red": (240, 32, 32),
    "green": (32, 240, 32),
    "blue": (32, 32, 240),
    "yellow": (240, 240, 32),
    "magenta": (240, 32, 240),
    "cyan": (32, 240, 240),
    "white": (240, 240, 240),
}

#: Colours that look like a target to a loosely tuned filter.
DISTRACTOR_RGB = {
    # RGB444 (9, 4, 2): red only when diff_min <= 5 (the paper's false-target case).
    "wood": (150, 70, 40),
    # RGB444 (10, 10, 10): white only when white_min <= 10.
    "light_grey": (160, 160, 160),
}

_NAMED_RGB = {**TARGET_RGB, **DISTRACTOR_RGB}

BACKGROUNDS = ("noise", "dark", "black", "grey", "random")
SCENARIOS = ("centre", "left", "right", "sweep", "approach", "lost")


def make_rng(rng=None):
    """A ``numpy.random.Generator`` from ``None`` (seed 0), an int seed or a Generator."""
    if rng is None:
        return np.random.default_rng(0)
    if isinstance(rng, np.random.Generator):
        return rng
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        return np.random.default_rng(int(rng))
    raise TypeError(f"rng must be None, an int seed or a numpy Generator, not {rng!r}")


def as_rgb444(frame):
    """Pack an RGB888 frame (H, W, 3) into (H, W) uint16 RGB444 (``c >> 4`` per channel)."""
    frame = np.asarray(frame)
    if frame.ndim != 3:
        raise ValueError(f"expected an (H, W, 3) RGB888 frame, got shape {frame.shape}")
    return to_rgb444(frame, frame.shape[1], frame.shape[0])


def _rgb(color):
    if isinstance(color, str):
        try:
            return _NAMED_RGB[color.lower()]
        except KeyError:
            raise ValueError(
                f"unknown colour {color!r}; choose one of: {', '.join(_NAMED_RGB)}, "
                f"or give an (r, g, b) tuple of 0..255"
            ) from None
    rgb = tuple(int(c) for c in color)
    if len(rgb) != 3 or not all(0 <= c <= 255 for c in rgb):
        raise ValueError(f"a colour must be 3 values 0..255, got {color!r}")
    return rgb


def _check_size(width, height):
    check_int("width", width, 1)
    check_int("height", height, 1)


def background_frame(width, height, background="noise", rng=None, *, speckle=0.0):
    """A frame of background only.

    ``background`` is one of :data:`BACKGROUNDS`:

    - ``"noise"``: grey levels 16..160 with up to +-24 of independent jitter per channel,
      clipped to 0..191. Channels stay within 3 RGB444 steps of each other and below 12, so
      no colour matches at the default thresholds.
    - ``"dark"``: each channel uniform in 0..40 (RGB444 0..2).
    - ``"black"``: all zero. ``"grey"``: flat (128, 128, 128).
    - ``"random"``: every channel uniform in 0..255 (some pixels match any colour).

    ``speckle`` (0..1) is the fraction of pixels replaced by uniform random colours.
    """
    _check_size(width, height)
    rng = make_rng(rng)
    if background == "noise":
        level = rng.integers(16, 161, (height, width, 1), dtype=np.int16)
        jitter = rng.integers(-24, 25, (height, width, 3), dtype=np.int16)
        frame = np.clip(level + jitter, 0, 191).astype(np.uint8)
    elif background == "dark":
        frame = rng.integers(0, 41, (height, width, 3), dtype=np.uint8)
    elif background == "black":
        frame = np.zeros((height, width, 3), np.uint8)
    elif background == "grey":
        frame = np.full((height, width, 3), 128, np.uint8)
    elif background == "random":
        frame = rng.integers(0, 256, (height, width, 3), dtype=np.uint8)
    else:
        raise ValueError(f"unknown background {background!r}; choose one of: {BACKGROUNDS}")
    if not 0.0 <= speckle <= 1.0:
        raise ValueError(f"speckle must be a fraction 0..1, got {speckle!r}")
    if speckle > 0:
        where = rng.random((height, width)) < speckle
        frame[where] = rng.integers(0, 256, (int(where.sum()), 3), dtype=np.uint8)
    return frame


def empty_frame(width, height, background="noise", rng=None):
    """A frame without any target (see :func:`background_frame`)."""
    return background_frame(width, height, background, rng)


def random_frame(width, height, rng=None):
    """A frame of uniform random RGB888 pixels."""
    return background_frame(width, height, "random", rng)


@dataclass(frozen=True)
class Blob:
    """A solid coloured shape centred on (``cx``, ``cy``) in pixel coordinates.

    Give ``radius`` for a disc (the pixels whose centre is within ``radius``) or
    ``size=(w, h)`` for a ``w`` x ``h`` rectangle whose left column is ``round(cx - w / 2)``.
    ``color`` is a name of :data:`TARGET_RGB` / :data:`DISTRACTOR_RGB` or an (r, g, b) tuple.
    """

    color: object
    cx: float
    cy: float
    radius: float | None = None
    size: tuple | None = None

    def __post_init__(self):
        if (self.radius is None) == (self.size is None):
            raise ValueError("a Blob needs exactly one of radius= (disc) or size=(w, h)")
        if self.radius is not None and self.radius < 0:
            raise ValueError(f"radius must be >= 0, got {self.radius}")
        if self.size is not None:
            w, h = self.size
            if w < 0 or h < 0:
                raise ValueError(f"size must be non-negative (w, h), got {self.size}")
        _rgb(self.color)

    def mask(self, width, height):
        """Boolean (height, width) array of the pixels the blob covers (clipped to the frame)."""
        ys = np.arange(height)[:, None]
        xs = np.arange(width)[None, :]
        if self.radius is not None:
            return (xs - self.cx) ** 2 + (ys - self.cy) ** 2 <= self.radius**2
        w, h = (int(v) for v in self.size)
        x0 = round(self.cx - w / 2)
        y0 = round(self.cy - h / 2)
        return (xs >= x0) & (xs < x0 + w) & (ys >= y0) & (ys < y0 + h)


def draw_blobs(frame, blobs, rng=None, *, jitter=8):
    """Paint ``blobs`` in order onto ``frame`` (modified in place, also returned).

    Each covered pixel gets the blob colour plus an independent uniform jitter of up to
    ``+-jitter`` per channel (clipped to 0..255). With ``jitter <= 8`` every named target colour
    keeps RGB444 channels 14..15 and 1..2, so it still matches at the default thresholds.
    """
    rng = make_rng(rng)
    height, width = frame.shape[:2]
    for blob in blobs:
        mask = blob.mask(width, height)
        n = int(mask.sum())
        if n == 0:
            continue
        rgb = np.array(_rgb(blob.color), np.int16)
        pix = np.broadcast_to(rgb, (n, 3))
        if jitter:
            pix = pix + rng.integers(-jitter, jitter + 1, (n, 3), dtype=np.int16)
        frame[mask] = np.clip(pix, 0, 255).astype(np.uint8)
    return frame


def blob_frame(
    width,
    height,
    color="red",
    cx=None,
    cy=None,
    radius=None,
    *,
    size=None,
    background="noise",
    distractors=(),
    speckle=0.0,
    jitter=8,
    rng=None,
):
    """A frame with one target blob over a background, plus optional distractor blobs.

    ``cx``, ``cy`` default to the frame centre; give ``radius`` (disc) or ``size=(w, h)``
    (rectangle); with neither, a disc of radius ``height // 8``. ``distractors`` is a sequence
    of :class:`Blob` drawn before the target (so the target is on top).
    """
    _check_size(width, height)
    rng = make_rng(rng)
    cx = width / 2 if cx is None else cx
    cy = height / 2 if cy is None else cy
    if radius is None and size is None:
        radius = height // 8
    frame = background_frame(width, height, background, rng, speckle=speckle)
    target = Blob(color, cx, cy, radius=radius, size=size)
    return draw_blobs(frame, [*distractors, target], rng, jitter=jitter)


@dataclass(frozen=True)
class TargetState:
    """Where the target is in one frame of a sequence (``visible=False``: no target)."""

    visible: bool
    cx: float = 0.0
    cy: float = 0.0
    radius: float = 0.0


@dataclass(frozen=True)
class Scenario:
    """A named frame sequence: ``frames[i]`` shows ``states[i]``."""

    name: str
    frames: list
    states: list


def sequence(
    width,
    height,
    states,
    *,
    color="red",
    background="noise",
    distractors=(),
    speckle=0.0,
    jitter=8,
    rng=None,
):
    """One frame per :class:`TargetState`; the background noise is fresh in every frame."""
    rng = make_rng(rng)
    frames = []
    for s in states:
        frame = background_frame(width, height, background, rng, speckle=speckle)
        blobs = list(distractors)
        if s.visible:
            blobs.append(Blob(color, s.cx, s.cy, radius=s.radius))
        frames.append(draw_blobs(frame, blobs, rng, jitter=jitter))
    return frames


def scenario_states(name, width=160, height=120, *, n_frames=None, lost_frames=15):
    """The target states of a named scenario (see :func:`scenario`)."""
    cy = height / 2
    r = height * 0.12  # about 540 window pixels at 160x120: proximity 3
    if name in ("centre", "left", "right"):
        n = 8 if n_frames is None else n_frames
        cx = {"centre": width / 2, "left": width * 0.25, "right": width * 0.75}[name]
        return [TargetState(True, cx, cy, r)] * n
    if name == "sweep":
        n = 16 if n_frames is None else n_frames
        xs = np.linspace(width * 0.15, width * 0.85, n)
        return [TargetState(True, float(x), cy, r) for x in xs]
    if name == "approach":
        n = 12 if n_frames is None else n_frames
        radii = np.linspace(height * 0.06, height * 0.5, n)
        return [TargetState(True, width / 2, cy, float(rad)) for rad in radii]
    if name == "lost":
        seen = 4 if n_frames is None else n_frames
        right = TargetState(True, width * 0.75, cy, r)
        left = TargetState(True, width * 0.25, cy, r)
        gone = TargetState(False)
        return [right] * seen + [gone] * (lost_frames + 3) + [left] * seen
    raise ValueError(f"unknown scenario {name!r}; choose one of: {SCENARIOS}")


def scenario(
    name,
    width=160,
    height=120,
    *,
    color="red",
    n_frames=None,
    lost_frames=15,
    background="noise",
    distractors=(),
    rng=None,
):
    """A named multi-frame sequence of one target of ``color``.

    - ``"centre"``, ``"left"``, ``"right"``: a still target at x = W/2, W/4 or 3W/4
      (``n_frames`` frames, default 8).
    - ``"sweep"``: the target moves from 0.15 W to 0.85 W (default 16 frames).
    - ``"approach"``: at the centre, radius growing from 0.06 H to 0.5 H (default 12 frames),
      so the count passes every default proximity threshold.
    - ``"lost"``: ``n_frames`` (default 4) frames at the right, ``lost_frames + 3`` frames
      without target (long enough to start the search), then ``n_frames`` at the left.
    """
    states = scenario_states(name, width, height, n_frames=n_frames, lost_frames=lost_frames)
    frames = sequence(
        width,
        height,
        states,
        color=color,
        background=background,
        distractors=distractors,
        rng=rng,
    )
    return Scenario(name, frames, states)
