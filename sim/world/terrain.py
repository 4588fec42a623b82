"""Terrain: floor patches that change how the robot drives (``[[room.terrain]]``).

A patch is a polygon on the floor with a traction factor (carpet, tiles, a wet floor) and a
slope (a ramp rising towards ``slope_dir``). While the robot's centre is on a patch:

- the wheels push with at most ``friction`` times the robot's traction force and torque;
- gravity's component along the slope, ``m g sin(slope)``, pushes the robot downhill; the
  wheels hold it with their (scaled) traction, so a robot parked on a ramp slides when
  ``m g sin(slope) > friction * traction_force`` and holds otherwise;
- a camera pitches with the slope along the way it faces,
  ``atan(tan(slope) cos(heading - slope_dir))`` with its own heading (facing uphill it looks
  up, across the slope it does not pitch).

The floor is drawn flat (a ramp's height is not modelled, only its tilt); overlapping patches:
the last one listed wins.
"""

import math
from dataclasses import dataclass

import numpy as np

from ..camera.floor_patches import patch_index

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


def slope_roll(patch, heading):
    """The robot's roll on ``patch`` facing ``heading``, rad (positive: its left side up,
    the slope rising to its left)."""
    if patch is None or patch.slope == 0.0:
        return 0.0
    return math.atan(math.tan(patch.slope) * math.sin(patch.slope_dir - heading))


#: The lookup grid has at most this many cells (its cell is at least ``MIN_CELL`` m).
MAX_CELLS = 1_000_000
MIN_CELL = 0.02
_MIXED = -2  # a cell that an edge of a patch crosses: looked up exactly


class TerrainMap:
    """The patches of a room, looked up by position (the last listed wins).

    A grid over the room answers most lookups with one index: a cell whose four corners lie
    in the same patch (or none) and that no patch edge comes near holds that patch; the cells
    along the edges (and any point outside the room) are tested polygon by polygon, so the
    answer is always the exact one.
    """

    def __init__(self, patches, width=None, depth=None):
        self.patches = tuple(patches)
        # Bounding boxes first: most exact lookups are far from most patches.
        self._boxes = [
            (
                min(p[0] for p in t.polygon),
                min(p[1] for p in t.polygon),
                max(p[0] for p in t.polygon),
                max(p[1] for p in t.polygon),
            )
            for t in self.patches
        ]
        self._grid = None
        if self.patches and width and depth:
            self._grid = self._build_grid(width, depth)

    def _build_grid(self, width, depth):
        cell = max(MIN_CELL, math.sqrt(width * depth / MAX_CELLS))
        nx, ny = math.ceil(width / cell), math.ceil(depth / cell)
        gx, gy = np.meshgrid(np.arange(nx + 1) * cell, np.arange(ny + 1) * cell)
        corner = patch_index([t.polygon for t in self.patches], gx, gy)
        pure = (
            (corner[:-1, :-1] == corner[1:, :-1])
            & (corner[:-1, :-1] == corner[:-1, 1:])
            & (corner[:-1, :-1] == corner[1:, 1:])
        )
        grid = np.where(pure, corner[:-1, :-1], _MIXED)
        # Every cell an edge passes through or near (samples a quarter cell apart, and their
        # neighbours) is tested exactly.
        near = np.zeros((ny + 2, nx + 2), dtype=bool)
        for t in self.patches:
            pts = list(t.polygon)
            for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]):
                n = max(2, math.ceil(math.hypot(x1 - x0, y1 - y0) / (cell / 4)) + 1)
                i = np.clip(np.floor(np.linspace(x0, x1, n) / cell).astype(int), -1, nx) + 1
                j = np.clip(np.floor(np.linspace(y0, y1, n) / cell).astype(int), -1, ny) + 1
                for di in (-1, 0, 1):
                    for dj in (-1, 0, 1):
                        near[np.clip(j + dj, 0, ny + 1), np.clip(i + di, 0, nx + 1)] = True
        grid[near[1:-1, 1:-1]] = _MIXED
        self._cell, self._nx, self._ny = cell, nx, ny
        return grid.astype(np.int32).tolist()  # list indexing: the fastest from Python

    def __bool__(self):
        return bool(self.patches)

    def at(self, x, y):
        """The patch under ``(x, y)``, or None."""
        if self._grid is not None:
            i, j = int(x / self._cell), int(y / self._cell)
            if 0 <= i < self._nx and 0 <= j < self._ny and x >= 0 and y >= 0:
                k = self._grid[j][i]
                if k != _MIXED:
                    return self.patches[k] if k >= 0 else None
        return self._exact(x, y)

    def _exact(self, x, y):
        for patch, (x0, y0, x1, y1) in zip(reversed(self.patches), reversed(self._boxes)):
            if x0 <= x <= x1 and y0 <= y <= y1 and polygon_contains(patch.polygon, x, y):
                return patch
        return None
