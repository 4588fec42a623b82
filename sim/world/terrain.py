"""Terrain: floor patches that change how the robot drives (``[[room.terrain]]``).

A patch is a polygon on the floor with a traction factor (carpet, tiles, a wet floor) and a
slope (a ramp rising towards ``slope_dir``). While the robot's centre is on a patch:

- the wheels push with at most ``friction`` times the robot's traction force and torque;
- gravity's component along the slope, ``m g sin(slope)``, pushes the robot downhill; the
  wheels hold it with their (scaled) traction, so a robot parked on a ramp slides when
  ``m g sin(slope) > friction * traction_force`` and holds otherwise;
- the camera pitches with the slope along the robot's heading,
  ``atan(tan(slope) cos(heading - slope_dir))`` (facing uphill it looks up).

The floor is drawn flat (a ramp's height is not modelled, only its tilt); overlapping patches:
the last one listed wins.
"""

import math
from dataclasses import dataclass

__all__ = ["TerrainMap", "TerrainPatch", "polygon_contains", "slope_pitch"]


@dataclass(frozen=True)
class TerrainPatch:
    name: str
    polygon: tuple  # ((x, y), ...), counter-clockwise or not, at least 3 corners
    friction: float  # traction factor (1: the robot's own traction)
    slope: float  # rad, 0 = level
    slope_dir: float  # rad: the direction (world, counter-clockwise from +x) the ramp rises
    color: tuple | None  # albedo drawn on the floor and the map; None: not drawn

    def downhill_force(self, mass, g):
        """``(fx, fy)``, N: gravity's component along the slope, pointing downhill."""
        f = mass * g * math.sin(self.slope)
        return -f * math.cos(self.slope_dir), -f * math.sin(self.slope_dir)


def polygon_contains(polygon, x, y):
    """Whether ``(x, y)`` is inside ``polygon`` (even-odd rule; a point on an edge may go
    either way)."""
    inside = False
    n = len(polygon)
    x0, y0 = polygon[-1]
    for i in range(n):
        x1, y1 = polygon[i]
        if (y1 > y) != (y0 > y) and x < (x0 - x1) * (y - y1) / (y0 - y1) + x1:
            inside = not inside
        x0, y0 = x1, y1
    return inside


def slope_pitch(patch, heading):
    """The camera's extra pitch on ``patch`` facing ``heading``, rad (positive looks up)."""
    if patch is None or patch.slope == 0.0:
        return 0.0
    return math.atan(math.tan(patch.slope) * math.cos(heading - patch.slope_dir))


class TerrainMap:
    """The patches of a room, looked up by position (the last listed wins)."""

    def __init__(self, patches):
        self.patches = tuple(patches)
        # Bounding boxes first: most lookups are far from most patches.
        self._boxes = [(min(p[0] for p in t.polygon), min(p[1] for p in t.polygon),
                        max(p[0] for p in t.polygon), max(p[1] for p in t.polygon))
                       for t in self.patches]

    def __bool__(self):
        return bool(self.patches)

    def at(self, x, y):
        """The patch under ``(x, y)``, or None."""
        for patch, (x0, y0, x1, y1) in zip(reversed(self.patches), reversed(self._boxes)):
            if x0 <= x <= x1 and y0 <= y <= y1 and polygon_contains(patch.polygon, x, y):
                return patch
        return None
