"""Auto white balance (AWB): grey-world red, green and blue gains that converge over frames.

The chip's AWB "adjusts the gain to make red, green and blue average values equal based on a
grey world assumption" (OmniVision's OV767x datasheets). Its channel gains are registers of
``value / 0x40`` (BLUE 0x01, RED 0x02, GREEN 0x6A), at least 1 and below 4 (0xFF / 0x40). The
model measures the mean linear signal of each colour on the mosaic (after the current gains),
works out the gains that would make the three means equal with the smallest gain 1, and moves
the gains a fraction ``speed`` of the way there, in logarithm, each frame: ``g <- g *
(target / g) ** speed``. With a steady scene the log-error shrinks by ``(1 - speed)`` a frame
(time constant ``-1 / ln(1 - speed)`` frames). The datasheet gives no figure for the speed (a
register sets it); 0.25 settles a step in colour within about 10 frames (a third of a second).
"""

from dataclasses import dataclass, field

import numpy as np

__all__ = ["AutoWhiteBalance", "grey_world_gains"]

#: Largest channel gain the registers hold (0xFF / 0x40).
MAX_WB_GAIN = 0xFF / 0x40


def grey_world_gains(means, gains=(1.0, 1.0, 1.0), max_gain=MAX_WB_GAIN):
    """The gains that make the channel ``means`` (measured with ``gains``) equal, smallest 1."""
    means = np.maximum(np.asarray(means, dtype=np.float64), 1e-9)
    target = np.asarray(gains, dtype=np.float64) / means
    return np.minimum(target / target.min(), max_gain)


@dataclass
class AutoWhiteBalance:
    """The white-balance state of a run: ``gains`` (R, G, B), updated by ``update(means)``."""

    speed: float = 0.25
    enabled: bool = True
    max_gain: float = MAX_WB_GAIN
    gains: np.ndarray = field(default_factory=lambda: np.ones(3))

    def update(self, means):
        """``means``: the mean linear R, G, B signal of the frame just taken (any scale)."""
        if not self.enabled:
            return
        target = grey_world_gains(means, self.gains, self.max_gain)
        gains = self.gains * (target / self.gains) ** self.speed
        self.gains = np.minimum(gains / gains.min(), self.max_gain)
