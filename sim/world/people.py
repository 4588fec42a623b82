"""People walking scripted paths: a position as a function of time, and their look.

A person stands at their first waypoint until ``start_delay``, walks to the next waypoint at
their speed, pauses there for that waypoint's pause, and so on; with ``loop`` they walk back
to the first waypoint and go round again, otherwise they stay at the last one. The path is a
pure function of time (legs are generated lazily, in order, so a per-leg speed jitter drawn
from the world's generator is deterministic for a seed). In the physics a person is a
kinematic body: the robot bumps into them, but they are never pushed off their script. (A
person with a ``yield_gap`` may wait for the robot: the world then asks for the position at a
script time that runs behind the clock by the time waited.)
"""

import math

from ..camera.scene import Band

__all__ = ["REFERENCE_HEIGHT", "PersonPath", "person_bands"]

#: Band heights below are given for a person of this height and scale with ``height``.
REFERENCE_HEIGHT = 1.75
_TROUSERS = (0.0, 0.85)
_SHIRT = (0.85, 1.45)
_HEAD = (1.5, 1.75)


def person_bands(config):
    """The person's look as cylinder bands: trousers, shirt, head (scaled to the height)."""
    s = config.height / REFERENCE_HEIGHT
    return (
        Band(_TROUSERS[0] * s, _TROUSERS[1] * s, tuple(config.trousers_color)),
        Band(_SHIRT[0] * s, _SHIRT[1] * s, tuple(config.shirt_color)),
        Band(_HEAD[0] * s, _HEAD[1] * s, tuple(config.skin_color)),
    )


class PersonPath:
    """A person's scripted position over time.

    Parameters
    ----------
    config : PersonConfig
    rng : numpy.random.Generator
        Draws each leg's speed jitter (only if ``config.speed_jitter > 0``).
    """

    def __init__(self, config, rng):
        self.config = config
        self.rng = rng
        x0, y0 = config.waypoints[0]
        # Segments (t0, t1, x0, y0, x1, y1): linear motion (or a pause when the ends agree).
        self.segments = [(0.0, config.start_delay, x0, y0, x0, y0)]
        self._at = 0  # index of the waypoint the last segment ends at
        pts = config.waypoints
        cycle = sum(math.dist(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts)))
        # One waypoint, or a loop that takes no time: nothing ever moves again.
        self._finished = len(pts) == 1 or (config.loop and cycle == 0 and not any(config.pauses))
        self._cursor = 0

    def _next_waypoint(self):
        n = len(self.config.waypoints)
        nxt = self._at + 1
        if nxt < n:
            return nxt
        return 0 if self.config.loop else None

    def _extend(self):
        cfg = self.config
        nxt = self._next_waypoint()
        t0 = self.segments[-1][1]
        if nxt is None:
            self._finished = True
            return
        xa, ya = cfg.waypoints[self._at]
        xb, yb = cfg.waypoints[nxt]
        speed = cfg.speed
        if cfg.speed_jitter > 0:
            speed *= 1.0 + cfg.speed_jitter * float(self.rng.uniform(-1.0, 1.0))
        t1 = t0 + math.hypot(xb - xa, yb - ya) / speed
        self.segments.append((t0, t1, xa, ya, xb, yb))
        self.segments.append((t1, t1 + cfg.pauses[nxt], xb, yb, xb, yb))
        self._at = nxt
        if not cfg.loop and nxt == len(cfg.waypoints) - 1:
            self._finished = True

    def position(self, t):
        """``(x, y)`` at time ``t`` (s)."""
        segments = self.segments
        while t > segments[-1][1] and not self._finished:
            self._extend()
        i = self._cursor
        if t < segments[i][0]:
            i = 0
        last = len(segments) - 1
        while i < last and t > segments[i][1]:
            i += 1
        self._cursor = i
        t0, t1, x0, y0, x1, y1 = segments[i]
        if t >= t1 or t1 <= t0:
            return (x1, y1)
        f = (t - t0) / (t1 - t0)
        if f <= 0.0:
            return (x0, y0)
        return (x0 + f * (x1 - x0), y0 + f * (y1 - y0))
