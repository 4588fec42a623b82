"""The KY-033 line-tracking sensor: a TCRT5000 reflective infrared pair and an LM393
comparator. Its digital output is HIGH when too little infrared comes back (a dark line,
or nothing under the sensor within its reach) and LOW over a reflective floor; the module's
potentiometer sets the threshold.

Here the light that comes back is the floor's reflectance under the sensor: the albedo's
luminance (Rec. 709 weights, standing in for the infrared reflectance) averaged over the spot
the photodiode sees, plus seeded Gaussian noise; the output is 1 when that is below
``threshold``. Higher than ``max_height`` above the floor nothing comes back: always 1.
"""

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["KY033", "KY033Params", "luminance", "spot_offsets"]

#: Rec. 709 luma weights.
_LUMA = np.array([0.2126, 0.7152, 0.0722])


def luminance(color):
    """The luminance of an albedo ``(r, g, b)``, 0..1."""
    return float(np.dot(_LUMA, color))


def spot_offsets(radius):
    """The points averaged over a spot of ``radius``: its centre and six around it at two
    thirds of the radius (equal areas, roughly)."""
    r = 2.0 * radius / 3.0
    return [(0.0, 0.0)] + [
        (r * math.cos(k * math.pi / 3), r * math.sin(k * math.pi / 3)) for k in range(6)
    ]


@dataclass(frozen=True)
class KY033Params:
    threshold: float = 0.3  # reflectance below which the output is HIGH (the potentiometer)
    noise_std: float = 0.02  # reflectance units: Gaussian noise on each reading
    spot_radius: float = 0.003  # m: the floor area the photodiode averages over
    height: float = 0.008  # m above the floor (the TCRT5000 reads up to ~15 mm)
    max_height: float = 0.015  # m: higher than this, no reflection comes back


class KY033:
    """One sensor's digital output over the world's floor (``output``).

    Parameters
    ----------
    params : KY033Params
    rng : numpy.random.Generator
        The noise's stream (only drawn from when ``noise_std > 0``).
    """

    def __init__(self, params=KY033Params(), rng=None):
        if params.noise_std > 0 and rng is None:
            raise ValueError("a KY-033 with noise_std > 0 needs an rng")
        self.params = params
        self.rng = rng
        offsets = np.array(spot_offsets(params.spot_radius))
        self._dx, self._dy = offsets[:, 0], offsets[:, 1]

    def reflectance(self, world, x, y):
        """The mean luminance of the floor over the spot centred on ``(x, y)`` (no noise)."""
        colors = world.floor_colors_at(x + self._dx, y + self._dy)
        return float(np.mean(colors @ _LUMA))

    def output(self, world, x, y):
        """The module's output (0 or 1) over the floor at ``(x, y)``: 1 over a dark surface."""
        return self.outputs(world, [(x, y)])[0]

    def outputs(self, world, points):
        """The outputs of identical modules over each of ``points`` ((x, y), ...), read in
        one pass (the noise drawn in the points' order)."""
        p = self.params
        if p.height > p.max_height:
            return [1] * len(points)
        centres = np.asarray(points, dtype=float).reshape(-1, 2)
        colors = world.floor_colors_at(
            (centres[:, :1] + self._dx).ravel(), (centres[:, 1:] + self._dy).ravel()
        )
        values = (colors @ _LUMA).reshape(len(centres), -1).mean(axis=1)
        if p.noise_std > 0:
            values = values + p.noise_std * self.rng.standard_normal(len(centres))
        return [int(v < p.threshold) for v in values]
