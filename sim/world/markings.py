"""Floor markings (``[[room.lines]]``): tape or paint on the floor, as polylines of a width.

A ``FloorLine`` is a centreline (open or closed) and a width. A floor point is on the line
when its distance to the centreline is at most half the width (so the ends and sharp corners
are round, as the Minkowski sum of the centreline and a disc). ``polygons()`` gives the same
band as polygons for the renderers: strips of segments joined by mitres where the line bends
by at most ``MITRE_TURN``, and discs at the sharper corners and at the open ends, so that a
curve drawn from many short segments has neither gaps nor slivers.
"""

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["DISC_SIDES", "MITRE_TURN", "FloorLine"]

#: The sharpest bend (rad) joined by a mitre; a mitre sticks out past the round band by at
#: most ``w/2 (1/cos(MITRE_TURN/2) - 1)`` (8.2 % of the half width at 45°).
MITRE_TURN = math.radians(45.0)
#: Sides of the polygon that stands for a disc (a round corner or end).
DISC_SIDES = 16
#: A strip polygon turns by at most this much (rad) and holds at most this many segments, so
#: that it stays a simple polygon the 3D renderer can cut into triangles.
_STRIP_TURN = math.radians(90.0)
_STRIP_SEGMENTS = 32


@dataclass(frozen=True)
class FloorLine:
    """One marking: ``points`` ((x, y), ...) of its centreline (m), ``width`` (m), ``color``
    (albedo r, g, b in 0..1), ``closed`` (the last point joins the first), ``name``."""

    name: str
    points: tuple
    width: float
    color: tuple = (0.0, 0.0, 0.0)
    closed: bool = False

    def __post_init__(self):
        pts = np.asarray(self.points, dtype=float)
        if self.closed:
            pts = np.vstack([pts, pts[:1]])
        a, b = pts[:-1], pts[1:]
        d = b - a
        seg_len = np.hypot(d[:, 0], d[:, 1])
        keep = seg_len > 0.0  # repeated points add nothing
        a, d, seg_len = a[keep], d[keep], seg_len[keep]
        object.__setattr__(self, "_a", a)
        object.__setattr__(self, "_d", d)
        object.__setattr__(self, "_len", seg_len)
        object.__setattr__(self, "_start", np.concatenate([[0.0], np.cumsum(seg_len)[:-1]]))
        half = self.width / 2.0
        lo = pts.min(axis=0) - half
        hi = pts.max(axis=0) + half
        object.__setattr__(self, "bounds", (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])))

    @property
    def length(self):
        """The centreline's length, m (a closed line's includes the closing segment)."""
        return float(self._len.sum())

    def _nearest(self, x, y):
        """``(distance, arc)`` of the nearest centreline point to each of ``x``, ``y``."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        px, py = x[..., None] - self._a[:, 0], y[..., None] - self._a[:, 1]
        t = np.clip((px * self._d[:, 0] + py * self._d[:, 1]) / (self._len * self._len), 0, 1)
        dist = np.hypot(px - t * self._d[:, 0], py - t * self._d[:, 1])
        k = np.argmin(dist, axis=-1)
        best = np.take_along_axis(dist, k[..., None], axis=-1)[..., 0]
        tk = np.take_along_axis(t, k[..., None], axis=-1)[..., 0]
        return best, self._start[k] + tk * self._len[k]

    def distance(self, x, y):
        """Distance (m) from ``(x, y)`` to the centreline (arrays give arrays)."""
        d, _ = self._nearest(x, y)
        return float(d) if d.ndim == 0 else d

    def covers(self, x, y):
        """Whether ``(x, y)`` is on the marking (within half the width of the centreline)."""
        d, _ = self._nearest(x, y)
        inside = d <= self.width / 2.0
        return bool(inside) if inside.ndim == 0 else inside

    def arc_position(self, x, y):
        """The arc length (m from the first point, along the line) of the centreline point
        nearest ``(x, y)``: on a closed line, laps are counted by its wrap-around."""
        _, s = self._nearest(x, y)
        return float(s) if s.ndim == 0 else s

    # -- the painted band, for the renderers ------------------------------------------------

    def polygons(self):
        """The band as polygons ``[((x, y), ...), ...]``: mitred strips and discs."""
        a, d, n = self._a, self._d, len(self._len)
        if n == 0:  # a single point repeated: a dot
            return [_disc(tuple(self.points[0]), self.width / 2.0)]
        u = d / self._len[:, None]
        normal = np.stack([-u[:, 1], u[:, 0]], axis=1)
        half = self.width / 2.0
        ends = a + d
        # turn[i]: the bend at the joint between segment i and i + 1 (wrapping when closed).
        joints = n if self.closed else n - 1
        turn = [
            math.atan2(
                u[i, 0] * u[(i + 1) % n, 1] - u[i, 1] * u[(i + 1) % n, 0],
                float(u[i] @ u[(i + 1) % n]),
            )
            for i in range(joints)
        ]
        mitred = [abs(t) <= MITRE_TURN for t in turn]

        def offset(i, side, at_end):
            """A corner of segment ``i``'s band: the mitre point at a mitred joint, else
            the segment's own (butt) corner."""
            j = i if at_end else i - 1  # the joint at that end
            if self.closed:
                j %= n
            p = ends[i] if at_end else a[i]
            if 0 <= j < joints and mitred[j]:
                m = normal[j] + normal[(j + 1) % n]
                m = m / (m @ normal[i])  # reaches w/2 across both segments' edges
                return tuple(p + side * half * m)
            return tuple(p + side * half * normal[i])

        # Strips: runs of segments with mitred joints, cut where a strip turns too far. A
        # closed line with a sharp corner starts right after it.
        start = (mitred.index(False) + 1) % n if self.closed and not all(mitred) else 0
        polys = []
        strip, bend = [start], 0.0
        for step in range(1, n):
            k = (start + step) % n
            j = (k - 1) % n  # the joint between the strip's last segment and k
            bend += turn[j]
            if mitred[j] and abs(bend) < _STRIP_TURN and len(strip) < _STRIP_SEGMENTS:
                strip.append(k)
            else:
                polys.append(self._strip_polygon(strip, offset))
                strip, bend = [k], 0.0
        polys.append(self._strip_polygon(strip, offset))
        # Discs at the sharp joints and at the open ends.
        for j in range(joints):
            if not mitred[j]:
                polys.append(_disc(tuple(ends[j]), half))
        if not self.closed:
            polys.append(_disc(tuple(a[0]), half))
            polys.append(_disc(tuple(ends[-1]), half))
        return polys

    def _strip_polygon(self, strip, offset):
        left = [offset(strip[0], 1.0, False)] + [offset(i, 1.0, True) for i in strip]
        right = [offset(strip[0], -1.0, False)] + [offset(i, -1.0, True) for i in strip]
        return [tuple(map(float, p)) for p in left + right[::-1]]


def _disc(center, radius):
    cx, cy = center
    return [
        (
            float(cx + radius * math.cos(2 * math.pi * k / DISC_SIDES)),
            float(cy + radius * math.sin(2 * math.pi * k / DISC_SIDES)),
        )
        for k in range(DISC_SIDES)
    ]
