"""Mistakes in a world description that are legal but almost never meant.

``world_warnings(config)`` looks at a parsed ``WorldConfig`` and returns one line per
problem, each naming the key path: a person's waypoint inside furniture, a person's path
through furniture or so close to the robot's start that the bodies would touch. (A robot or a waypoint outside the room, and
a robot starting inside furniture or a person, are errors of their own, raised while the
world is parsed and built.) Furniture that leaves the room (``present_until``) is left out:
a path through the place it stood may be the point of the scenario.
"""

import math

from .config import start_name

__all__ = ["point_in_polygon", "segment_distance", "world_warnings"]


def point_in_polygon(point, polygon):
    """Whether ``point`` lies inside the convex or concave ``polygon`` (even-odd rule)."""
    x, y = point
    inside = False
    n = len(polygon)
    for i in range(n):
        (x0, y0), (x1, y1) = polygon[i], polygon[(i + 1) % n]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def _point_segment(p, a, b):
    (px, py), (ax, ay), (bx, by) = p, a, b
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    f = 0.0 if length2 == 0.0 else max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / length2))
    return math.hypot(px - ax - f * dx, py - ay - f * dy)


def _segments_cross(a, b, c, d):
    def side(p, q, r):
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    return (side(a, b, c) * side(a, b, d) < 0) and (side(c, d, a) * side(c, d, b) < 0)


def segment_distance(a, b, polygon):
    """The distance from the segment ``a``-``b`` to the polygon's area, m (0 if they meet)."""
    if point_in_polygon(a, polygon) or point_in_polygon(b, polygon):
        return 0.0
    n = len(polygon)
    edges = [(polygon[i], polygon[(i + 1) % n]) for i in range(n)]
    if any(_segments_cross(a, b, c, d) for c, d in edges):
        return 0.0
    return min(
        min(_point_segment(c, a, b), _point_segment(a, c, d), _point_segment(b, c, d))
        for c, d in edges
    )


def _fmt(point):
    return "[" + ", ".join(f"{c:g}" for c in point) + "]"


def _legs(person):
    """``(j, k)`` index pairs of the legs a person walks (back to the start with ``loop``)."""
    n = len(person.waypoints)
    legs = [(j, j + 1) for j in range(n - 1)]
    if person.loop and n > 2:
        legs.append((n - 1, 0))
    return legs


def world_warnings(config):
    """One line per suspicious placement in ``config`` (a ``config.WorldConfig``)."""
    warnings = []
    furniture = [(f.name, f.corners()) for f in config.room.furniture if f.present_until is None]
    start = config.robot.start
    robot_radius = config.robot.spec.body_radius
    for i, person in enumerate(config.people):
        path = f"people[{i}].waypoints"
        inside = set()  # (waypoint, furniture) pairs already reported
        for j, p in enumerate(person.waypoints):
            for name, poly in furniture:
                if point_in_polygon(p, poly):
                    warnings.append(f"{path}[{j}] {_fmt(p)} lies inside furniture {name!r}")
                    inside.add((j, name))
                elif segment_distance(p, p, poly) < person.radius:
                    warnings.append(
                        f"{path}[{j}] {_fmt(p)} puts the person (radius "
                        f"{person.radius:g} m) into furniture {name!r}"
                    )
                    inside.add((j, name))
        for j, k in _legs(person):
            a, b = person.waypoints[j], person.waypoints[k]
            for name, poly in furniture:
                if (
                    (j, name) not in inside
                    and (k, name) not in inside
                    and segment_distance(a, b, poly) < person.radius
                ):
                    warnings.append(f"{path}[{j}] -> [{k}] walks through furniture {name!r}")
            d = _point_segment(start, a, b)
            # A yielding person stops yield_gap short of the robot instead of walking into it.
            if a != b and d < robot_radius + person.radius + person.yield_gap:
                outcome = (
                    f"is blocked by the robot (radius {robot_radius:g} m) where it starts: "
                    f"they wait (yield_gap {person.yield_gap:g} m) until it moves out of the way"
                    if person.yield_gap > 0
                    else f"walks into the robot (radius {robot_radius:g} m) where it starts"
                )
                warnings.append(
                    f"{path}[{j}] -> [{k}] passes {d:.2f} m from "
                    f"{start_name(config.robot.default_start)} {_fmt(start)}: "
                    f"the person (radius {person.radius:g} m) {outcome}"
                )
    return warnings
