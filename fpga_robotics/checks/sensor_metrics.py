"""Metrics and checks of the sensor designs' runs: how well a line follower holds its line
(lateral error, laps, time off the line) and whether following resumes once an obstacle is
gone. ``SENSOR_CHECKS`` joins ``summary.CHECKS``; ``sensor_check`` evaluates one.
"""

import math

import numpy as np

from fpga_robotics.sim.world import is_removal_event

__all__ = ["CHECK_METRIC", "RESUME_CLOSING_M", "SENSOR_CHECKS", "line_metrics",
           "obstacle_metrics", "sensor_check"]

_DAY = 86400.0
#: Following has resumed once the robot is this much closer to the target than when the last
#: obstacle left, m.
RESUME_CLOSING_M = 0.2

SENSOR_CHECKS = {
    "max_lateral_error_m": (float, (0, 100, "m"),
                            ("the line sensors' centre stays within this distance of the nearest "
                            "floor line's centreline")),
    "min_laps": (int, (0, 10**6, ""), "at least this many whole laps of the closed floor line"),
    "max_off_line_s": (float, (0, _DAY, "s"),
                       "at most this long in all with no line sensor over a floor line"),
    "resumes_within_s": (float, (0, _DAY, "s"),
                         (f"after the last piece of furniture is removed, the robot closes "
                         f"{RESUME_CLOSING_M} m on the target within this time")),
}


#: The metric each of ``SENSOR_CHECKS`` judges.
CHECK_METRIC = {"max_lateral_error_m": "lateral_error_max_m", "min_laps": "laps",
                "max_off_line_s": "off_line_s", "resumes_within_s": "resumed_after_s"}


def line_metrics(traj, lines, mounts, period):
    """``lateral_error_max_m``, ``lateral_error_mean_m``, ``off_line_s`` and ``laps`` of a run
    whose line sensors sit at ``mounts`` (``connectors.Mount``s) on the robot, over the floor
    ``lines`` (``FloorLine``s); rows ``period`` s apart. None values without lines or
    sensors."""
    none = {"lateral_error_max_m": None, "lateral_error_mean_m": None, "off_line_s": None,
            "laps": None}
    n = len(traj["t"])
    if not lines or not mounts or n == 0:
        return none
    x, y, h = (np.asarray(traj[k], dtype=float) for k in ("x", "y", "heading"))
    c, s = np.cos(h), np.sin(h)
    # Every sensor's world position in every row (the geometry of ``Mount.world_pose``).
    px = np.array([x + m.forward * c - m.left * s for m in mounts])
    py = np.array([y + m.forward * s + m.left * c for m in mounts])
    cx, cy = px.mean(axis=0), py.mean(axis=0)
    errors = np.min([line.distance(cx, cy) for line in lines], axis=0)
    on_line = np.any([line.covers(px.ravel(), py.ravel()).reshape(px.shape)
                      for line in lines], axis=(0, 1))
    off = int(np.count_nonzero(~on_line))
    track = next((line for line in lines if line.closed), None)
    laps = None
    if track is not None:
        steps = np.diff(track.arc_position(cx, cy))
        length = track.length
        steps = (steps + length / 2) % length - length / 2  # across the start: the short way
        laps = int(abs(float(steps.sum())) // length)
    return {"lateral_error_max_m": round(float(errors.max()), 4),
            "lateral_error_mean_m": round(float(errors.mean()), 4),
            "off_line_s": round(off * period, 4), "laps": laps}


def obstacle_metrics(traj, events):
    """``obstacle_removed_at_s`` (the last furniture removal) and ``resumed_after_s`` (from
    then until the robot is ``RESUME_CLOSING_M`` closer to the target; None if never)."""
    removed = [t for _, t, text in events if is_removal_event(text)]
    if not removed:
        return {"obstacle_removed_at_s": None, "resumed_after_s": None}
    t_r = max(removed)
    t, d = traj["t"], traj["target_distance"]
    after = np.flatnonzero(t >= t_r - 1e-9)
    resumed = None
    if len(after) and not math.isnan(d[after[0]]):
        start = d[after[0]]
        closer = after[d[after] <= start - RESUME_CLOSING_M]
        if len(closer):
            resumed = round(float(t[closer[0]] - t_r), 4)
    return {"obstacle_removed_at_s": round(t_r, 6), "resumed_after_s": resumed}


def sensor_check(name, limit, m):
    """``(passed, text)`` of one of ``SENSOR_CHECKS`` against the metrics ``m``."""
    if name == "resumes_within_s":
        t_r, v = m.get("obstacle_removed_at_s"), m.get("resumed_after_s")
        if t_r is None:
            return False, "no furniture was removed during the run (room.furniture.present_until)"
        if v is None:
            return False, (f"the robot never closed {RESUME_CLOSING_M} m on the target after "
                           f"the obstacle left at {t_r:.2f} s (limit {limit} s)")
        return v <= limit, (f"closed {RESUME_CLOSING_M} m on the target {v:.2f} s after the "
                            f"obstacle left (limit {limit} s)")
    v = m.get(CHECK_METRIC[name])
    if v is None:
        return False, "not measured: the run has no floor line or no line sensors"
    if name == "max_lateral_error_m":
        return v <= limit, (f"line sensors at most {v:.3f} m from the line (mean "
                            f"{m['lateral_error_mean_m']:.3f} m; limit {limit} m)")
    if name == "min_laps":
        return v >= limit, f"{v} whole lap(s) of the track (limit >= {limit})"
    return v <= limit, f"{v:.2f} s with no line sensor over the line (limit {limit} s)"
