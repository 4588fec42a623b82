"""The HC-SR04 ultrasound ranger: what it measures in the world and the ECHO pulse it answers
a TRIG pulse with, in edges of the design's clock.

The module (datasheet timing): a TRIG pulse of at least 10 us starts a measurement; the
module sends a burst of eight 40 kHz cycles (200 us) and then raises ECHO; ECHO falls when
the echo returns, so its width is the sound's round trip ``2 d / c``; with nothing in range
it falls after about 38 ms. A trigger while a measurement runs (until ECHO falls) is ignored.
The speed of sound in air is ``c = 331.3 + 0.606 T`` m/s (T in degrees C).

The world (``range_to``): the distance to the nearest surface inside the beam, a cone of
``cone_deg`` full angle around the sensor's heading, in the horizontal plane: the room's
walls, the furniture still in the room (solid footprints) and people (upright circles). An
object lower than the sensor only counts from the distance where the cone's lower edge comes
down to its top (``height - r tan(cone/2) <= top``): a low box close by is under the beam
until the beam spreads down onto it. Nearest points are found exactly (no sampled rays): a
footprint is clipped to the cone's wedge; a person off the cone's axis is met on its edges.
"""

import math
from dataclasses import dataclass

__all__ = ["HCSR04Module", "HCSR04Params", "range_to", "speed_of_sound"]


def speed_of_sound(temperature_c):
    """The speed of sound in dry air, m/s, at ``temperature_c`` degrees C (linear fit)."""
    return 331.3 + 0.606 * temperature_c


@dataclass(frozen=True)
class HCSR04Params:
    """The module's physics (not the design's ``UltrasoundParams``)."""

    cone_deg: float = 15.0  # full angle of the beam (datasheet: "measuring angle 15 degree")
    min_range: float = 0.02  # m: nearer surfaces give no reading (the time-out pulse)
    max_range: float = 4.0  # m
    temperature_c: float = 20.0  # air temperature, degrees C
    noise_std: float = 0.003  # m: Gaussian noise on each measured distance (datasheet: 3 mm)
    timeout_s: float = 0.038  # the ECHO pulse's width when nothing answers
    #: TRIG's fall to ECHO's rise: the 8-cycle 40 kHz burst (200 us) and the module's own
    #: start-up before it; 0.5 ms is typical of the modules' timing diagrams.
    echo_delay_s: float = 0.0005
    min_trigger_s: float = 10e-6  # the shortest TRIG pulse the module answers

    @property
    def speed_of_sound(self):
        return speed_of_sound(self.temperature_c)


def _clip_to_wedge(p0, p1, planes):
    """The part of segment p0-p1 (points relative to the sensor) on the inner side of every
    plane ``(nx, ny)`` (``n . p >= 0``), or None."""
    t0, t1 = 0.0, 1.0
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    for nx, ny in planes:
        a = nx * p0[0] + ny * p0[1]
        b = nx * dx + ny * dy
        if b == 0.0:
            if a < 0.0:
                return None
        elif b > 0.0:
            t0 = max(t0, -a / b)
        else:
            t1 = min(t1, -a / b)
        if t0 > t1:
            return None
    return ((p0[0] + t0 * dx, p0[1] + t0 * dy), (p0[0] + t1 * dx, p0[1] + t1 * dy))


def _clip_polygon(points, planes):
    """The convex polygon ``points`` (relative to the sensor) cut to the side ``n . p >= 0``
    of every plane (Sutherland-Hodgman); an empty list when nothing is left."""
    for nx, ny in planes:
        out = []
        for i, q in enumerate(points):
            p = points[i - 1]
            dp, dq = nx * p[0] + ny * p[1], nx * q[0] + ny * q[1]
            if (dp >= 0.0) != (dq >= 0.0):
                t = dp / (dp - dq)
                out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
            if dq >= 0.0:
                out.append(q)
        points = out
        if not points:
            break
    return points


def _polygon_near_far(points):
    """``(nearest, farthest)`` distance of a convex polygon's area from the origin."""
    far = max(math.hypot(*p) for p in points)
    inside = len(points) >= 3 and all(
        (q[0] - p[0]) * -p[1] - (q[1] - p[1]) * -p[0] >= 0.0
        for p, q in zip(points, points[1:] + points[:1])
    )
    if inside:
        return 0.0, far
    near = min(_segment_near_far(points[i - 1], points[i])[0] for i in range(len(points)))
    return near, far


def _segment_near_far(q0, q1):
    """``(nearest, farthest)`` distance of segment q0-q1 from the origin."""
    dx, dy = q1[0] - q0[0], q1[1] - q0[1]
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else min(1.0, max(0.0, -(q0[0] * dx + q0[1] * dy) / length2))
    near = math.hypot(q0[0] + t * dx, q0[1] + t * dy)
    return near, max(math.hypot(*q0), math.hypot(*q1))


def _ray_circle(direction, c, radius):
    """Distance along the unit ray ``direction`` from the origin to the circle (centre ``c``)
    where the ray first meets it, or None."""
    b = direction[0] * c[0] + direction[1] * c[1]
    disc = b * b - (c[0] * c[0] + c[1] * c[1] - radius * radius)
    if disc < 0.0:
        return None
    root = math.sqrt(disc)
    for t in (b - root, b + root):
        if t >= 0.0:
            return t
    return None


def _visible_from(near, far, reach):
    """The nearest distance at which a surface spanning ``near..far`` is in the beam, the
    beam reaching down to its top only from ``reach`` on; None if it never is."""
    if near >= reach:
        return near
    return reach if far >= reach else None


def range_to(world, x, y, heading, height, params=HCSR04Params()):
    """The distance (m) from a sensor at ``(x, y)``, ``height`` above the floor, facing
    ``heading`` (rad), to the nearest surface in its cone; None when that is nearer than
    ``min_range`` or farther than ``max_range`` (or there is none)."""
    half = math.radians(params.cone_deg) / 2.0
    slope = math.tan(half)
    c, s = math.cos(heading), math.sin(heading)
    # Inner normals of the wedge's two edges (the cone's half angle is below 90 degrees).
    left_edge = (math.cos(heading + half), math.sin(heading + half))
    right_edge = (math.cos(heading - half), math.sin(heading - half))
    planes = ((left_edge[1], -left_edge[0]), (-right_edge[1], right_edge[0]))

    def reach(top):
        """From which distance the beam's lower edge is below a top at ``top`` m."""
        return 0.0 if top >= height else (height - top) / slope

    best = math.inf
    room = world.config.room
    for a, b in _room_walls(room):
        clipped = _clip_to_wedge((a[0] - x, a[1] - y), (b[0] - x, b[1] - y), planes)
        if clipped is not None:
            best = min(best, _segment_near_far(*clipped)[0])
    for item in world.present_furniture():
        # corners() is counter-clockwise: the inside test of _polygon_near_far relies on it.
        inside = _clip_polygon([(px - x, py - y) for px, py in item.corners()], planes)
        if not inside:
            continue
        d = _visible_from(*_polygon_near_far(inside), reach(item.height))
        if d is not None and d < best:
            best = d
    for person in world.people:
        px, py = person.body.position
        centre = (px - x, py - y)
        r = person.config.radius
        dist = math.hypot(*centre)
        if dist - r >= best:
            continue
        # The circle's nearest point, if it lies in the wedge; else its first meeting with
        # either edge of the cone.
        if dist > r and (centre[0] * c + centre[1] * s) >= dist * math.cos(half):
            near = dist - r
        else:
            hits = [
                t
                for t in (_ray_circle(e, centre, r) for e in (left_edge, right_edge))
                if t is not None
            ]
            if dist <= r:
                hits.append(0.0)
            if not hits:
                continue
            near = min(hits)
        d = _visible_from(near, dist + r, reach(person.config.height))
        if d is not None and d < best:
            best = d
    if not params.min_range <= best <= params.max_range:
        return None
    return best


def _room_walls(room):
    w, d = room.width, room.depth
    corners = ((0.0, 0.0), (w, 0.0), (w, d), (0.0, d))
    return [(corners[i], corners[(i + 1) % 4]) for i in range(4)]


class HCSR04Module:
    """The module's answer to TRIG pulses, in edges of a clock (``on_trigger``).

    Parameters
    ----------
    params : HCSR04Params
    rng : numpy.random.Generator
        The distance noise's stream (only drawn from when ``noise_std > 0``).
    """

    def __init__(self, params=HCSR04Params(), rng=None):
        if params.noise_std > 0 and rng is None:
            raise ValueError("an HC-SR04 with noise_std > 0 needs an rng")
        self.params = params
        self.rng = rng
        #: The edge at which the module is free again (its last ECHO fell).
        self.busy_until = -1

    def echo_width(self, distance, clock_hz):
        """The ECHO pulse's width in edges for a surface at ``distance`` m (None: nothing
        in range, the time-out pulse); the noise is added to the distance."""
        p = self.params
        if distance is None:
            return round(p.timeout_s * clock_hz)
        if p.noise_std > 0:
            distance = max(0.0, distance + p.noise_std * float(self.rng.standard_normal()))
        return round(2.0 * distance / p.speed_of_sound * clock_hz)

    def on_trigger(self, rise_edge, fall_edge, distance, clock_hz):
        """A TRIG pulse high from ``rise_edge`` to ``fall_edge``: ``(echo_rise_edge,
        echo_fall_edge)``, or None when the module ignores it (shorter than
        ``min_trigger_s``, or begun before the last echo fell)."""
        p = self.params
        if (fall_edge - rise_edge) < p.min_trigger_s * clock_hz - 1e-9:
            return None
        if rise_edge < self.busy_until:
            return None
        # ECHO rises after TRIG's fall, on a later edge even with no delay (or a slow clock).
        rise = fall_edge + max(1, round(p.echo_delay_s * clock_hz))
        fall = rise + max(1, self.echo_width(distance, clock_hz))
        self.busy_until = fall
        return rise, fall
