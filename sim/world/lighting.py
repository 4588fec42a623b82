"""Lighting over time: ambient level and a directional light, changed by keyframes.

Keyframes are ``(t, ambient, intensity)``. With ``"linear"`` interpolation the values ramp
between keyframes; with ``"step"`` each keyframe's values hold until the next one. Before the
first keyframe the first one's values apply, after the last the last one's. Without
keyframes the constant ``ambient`` and ``intensity`` apply.
"""

import bisect

from ..camera.scene import Lighting

__all__ = ["SCHEDULE_SLACK", "LightingSchedule"]

#: A scheduled instant (a keyframe, a colour change, a removal) is reached when the clock is
#: within this of it, s: the clock is a float sum of physics steps, so a frame at 3.7 s may
#: read 3.6999999999999997.
SCHEDULE_SLACK = 1e-9


class LightingSchedule:
    """Lighting as a function of simulated time.

    Parameters
    ----------
    config : LightingConfig
    """

    def __init__(self, config):
        self.config = config
        self.direction = tuple(config.direction)
        self.keyframes = config.keyframes
        self._times = [k[0] for k in config.keyframes]
        self._cache = None

    def levels(self, t):
        """``(ambient, intensity)`` at time ``t``."""
        keys = self.keyframes
        if not keys:
            return self.config.ambient, self.config.intensity
        i = bisect.bisect_right(self._times, t + SCHEDULE_SLACK)  # keys[:i] are reached
        if i == 0:
            return keys[0][1], keys[0][2]
        if i == len(keys) or self.config.interpolation == "step":
            return keys[i - 1][1], keys[i - 1][2]
        t0, a0, b0 = keys[i - 1]
        t1, a1, b1 = keys[i]
        f = max(0.0, (t - t0) / (t1 - t0))  # t1 > t >= t0 (within the slack): t1 > t0
        return a0 + f * (a1 - a0), b0 + f * (b1 - b0)

    def at(self, t):
        """The ``sim.scene.Lighting`` at time ``t``."""
        ambient, intensity = self.levels(t)
        cached = self._cache
        if cached is not None and cached.ambient == ambient and cached.intensity == intensity:
            return cached
        self._cache = Lighting(ambient=ambient, intensity=intensity, direction=self.direction)
        return self._cache
