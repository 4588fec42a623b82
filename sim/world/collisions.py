"""The robot's collisions as episodes, with contact time, impulse and fault.

Pymunk reports every contact that begins; a body pushed along by a walking person or
scraping a wall loses and regains contact many times a second. A contact that resumes with
the same body (the same person, the same piece of furniture, the walls) within
``EPISODE_GAP`` of its end belongs to the same episode: one collision.

Fault is decided at the first touch of an episode by which body closed the gap: each one's
velocity component towards the other, averaged over the last ``FAULT_WINDOW`` before the
touch (a person's from their scripted path: their body follows it exactly; the robot's no
more than its own driving, so a robot shoved into someone did not close the gap). The
robot is at fault when it closed faster than the other body and faster than
``AT_FAULT_SPEED``.
"""

import math
from collections import deque

__all__ = [
    "AT_FAULT_SPEED",
    "EPISODE_GAP",
    "FAULT_WINDOW",
    "CollisionLog",
    "MotionHistory",
    "closing_speeds",
]

#: A contact that resumes within this time (s) of its end is the same collision.
EPISODE_GAP = 0.5

#: The robot is not at fault when it moves towards the other body slower than this, m/s.
AT_FAULT_SPEED = 0.02

#: Velocities for the fault are averaged over this long before the first touch, s.
FAULT_WINDOW = 0.1


def closing_speeds(robot_velocity, other_velocity, towards):
    """``(robot, other)``: each body's speed towards the other, m/s (negative: moving away).

    ``towards`` is the direction from the robot to the other body (need not be unit)."""
    ux, uy = towards
    norm = math.hypot(ux, uy)
    if norm == 0.0:
        return 0.0, 0.0
    ux, uy = ux / norm, uy / norm
    (rx, ry), (ox, oy) = robot_velocity, other_velocity
    return rx * ux + ry * uy, -(ox * ux + oy * uy)


class _Episode:
    __slots__ = ("ended", "kind", "name", "shapes", "since")

    def __init__(self, kind, name):
        self.kind = kind
        self.name = name
        self.shapes = set()  # the shapes of this body in contact now
        self.since = None  # start of the current stretch of contact, s
        self.ended = None  # end of the last stretch, s


class CollisionLog:
    """Collects a run's contacts of the robot into episodes, per kind of body.

    Parameters
    ----------
    kinds : iterable of str
        The kinds of body reported (``"person"``, ``"wall"``, ``"furniture"``).
    gap : float
        ``EPISODE_GAP``.
    """

    def __init__(self, kinds, gap=EPISODE_GAP):
        self.gap = gap
        self._stats = {k: {"episodes": 0, "contact_s": 0.0, "max_impulse_ns": 0.0} for k in kinds}
        self._at_fault = dict.fromkeys(self._stats, 0)
        self._bodies = {}  # (kind, name) -> _Episode
        self._per_name = {}  # (kind, name) -> episodes

    def begin(self, kind, name, shape, t):
        """A shape of body ``(kind, name)`` touches the robot at ``t``; True when this starts
        a new episode (the caller then decides the fault with ``record_fault``)."""
        ep = self._bodies.get((kind, name))
        if ep is None:
            ep = self._bodies[(kind, name)] = _Episode(kind, name)
        touching = bool(ep.shapes)
        ep.shapes.add(shape)
        if touching:
            return False
        ep.since = t
        if ep.ended is not None and t - ep.ended <= self.gap:
            return False
        self._stats[kind]["episodes"] += 1
        self._per_name[(kind, name)] = self._per_name.get((kind, name), 0) + 1
        return True

    def separate(self, kind, name, shape, t):
        """The shape stops touching the robot at ``t`` (also when it leaves the space)."""
        ep = self._bodies.get((kind, name))
        if ep is None or shape not in ep.shapes:
            return
        ep.shapes.discard(shape)
        if not ep.shapes:
            self._stats[kind]["contact_s"] += t - ep.since
            ep.ended = t
            ep.since = None

    def impulse(self, kind, impulse):
        """A physics step's contact impulse with a body of ``kind``, N s."""
        stats = self._stats[kind]
        stats["max_impulse_ns"] = max(stats["max_impulse_ns"], impulse)

    def record_fault(self, kind):
        """The episode just begun with a body of ``kind`` was the robot's fault."""
        self._at_fault[kind] += 1

    def episodes(self):
        """``{kind: episodes}``."""
        return {k: s["episodes"] for k, s in self._stats.items()}

    def episodes_with(self, kind, name):
        """Episodes with the one body ``(kind, name)``."""
        return self._per_name.get((kind, name), 0)

    def at_fault(self, kind):
        """Episodes with a body of ``kind`` that were the robot's fault."""
        return self._at_fault[kind]

    def summary(self, now):
        """``{kind: {episodes, contact_s, max_impulse_ns}}``; a contact still going on at
        ``now`` counts up to ``now``."""
        out = {}
        for kind, s in self._stats.items():
            ongoing = sum(
                now - ep.since
                for ep in self._bodies.values()
                if ep.kind == kind and ep.since is not None
            )
            out[kind] = {
                "episodes": s["episodes"],
                "contact_s": round(s["contact_s"] + ongoing, 4),
                "max_impulse_ns": round(s["max_impulse_ns"], 4),
            }
        return out


class MotionHistory:
    """The robot's, its own driving's (``World.driven_position``) and the people's positions
    at the start of the last sub-steps (the world records one before each physics step), for
    averaged velocities."""

    def __init__(self, window=FAULT_WINDOW):
        self.window = window
        self._rows = deque()  # (t, robot_xy, driven_xy, people_xy tuple), oldest first

    def record(self, t, robot_xy, driven_xy, people_xy):
        # Rows leave by age, not by count: the window is the same at any physics step.
        rows = self._rows
        while rows and t - rows[0][0] > self.window + 1e-12:
            rows.popleft()
        rows.append((t, robot_xy, driven_xy, people_xy))

    def mean_velocities(self, t, robot_xy, driven_xy, people_xy):
        """``(robot_v, driven_v, [person_v, ...])`` averaged from the oldest row within the
        window before ``t`` (at least the last one: the sub-step under way) up to the
        positions now."""
        start = self._rows[-1]
        for row in self._rows:
            if t - row[0] <= self.window + 1e-12:
                start = row
                break
        t0, r0, d0, p0 = start
        span = t - t0

        def velocity(a, b):
            return ((b[0] - a[0]) / span, (b[1] - a[1]) / span)

        people_v = [velocity(a, b) for a, b in zip(p0, people_xy)]
        return velocity(r0, robot_xy), velocity(d0, driven_xy), people_v
