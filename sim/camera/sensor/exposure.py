"""Auto-exposure and auto-gain (AEC/AGC): the OV7670's average-based control loop.

After each frame the chip compares the frame's average luminance (8-bit, of the output it
delivers) with two bands (datasheet registers):

- inside the *stable operating region* ``AEB..AEW`` (0x25, 0x24; 0x63..0x75 = 99..117 at
  power-on) nothing changes;
- outside it but inside the *control zone* (``VPT`` 0x26: its nibbles give the zone's limits
  ``{VPT[3:0], 0000} .. {VPT[7:4], 0000}``, 0x40..0xD0 = 64..208 at power-on) the exposure
  moves by a sixteenth of itself a frame, up or down;
- outside the control zone (fast mode, COM8[7], on at power-on) it doubles or halves a frame.

The total exposure ``exposure * gain`` is what moves: the exposure time first (from one row,
1/510 of the frame, to the whole frame period), then the analogue gain from 1 up to the gain
ceiling (COM9[6:4]). So a dark scene brightens by a factor 16/15 a frame in the control zone
(about 6.5 % a frame: from the zone's edge into the stable region in a few frames) and by 2 a
frame beyond it.
"""

from dataclasses import dataclass

__all__ = ["AutoExposure"]


@dataclass
class AutoExposure:
    """The exposure state of a run, updated once a frame by ``update(mean_luma)``.

    ``exposure`` is the exposure time as a fraction of the frame period, ``gain`` the analogue
    gain (>= 1).
    """

    window: tuple = (0x63, 0x75)
    fast_zone: tuple = (0x40, 0xD0)
    max_gain: float = 32.0
    min_exposure: float = 1 / 510
    exposure: float = 0.5
    gain: float = 1.0
    enabled: bool = True

    @property
    def total(self):
        """Exposure (fraction of a frame) times gain: what the picture's brightness follows."""
        return self.exposure * self.gain

    def set_total(self, total):
        """Exposure time first (up to a whole frame), then gain (up to the ceiling)."""
        total = min(max(total, self.min_exposure), self.max_gain)
        self.exposure = min(total, 1.0)
        self.gain = max(1.0, total / self.exposure)

    def step_factor(self, mean_luma):
        """The factor the total exposure moves by after a frame of average luminance
        ``mean_luma`` (8-bit scale)."""
        lo, hi = self.window
        fast_lo, fast_hi = self.fast_zone
        if lo <= mean_luma <= hi:
            return 1.0
        if mean_luma < fast_lo:
            return 2.0
        if mean_luma > fast_hi:
            return 0.5
        return 17 / 16 if mean_luma < lo else 15 / 16

    def update(self, mean_luma):
        if self.enabled:
            factor = self.step_factor(mean_luma)
            if factor != 1.0:
                self.set_total(self.total * factor)
