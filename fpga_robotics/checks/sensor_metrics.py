"""Metrics and checks of the sensor designs' runs: how well a line follower holds its line
(lateral error, laps, time off the line) and whether following resumes once an obstacle is
gone, and how often each sensor measured (``fpga_robotics.checks.shipped`` declares their
checks).
"""

import numpy as np

from fpga_robotics.sim.world import is_removal_event

__all__ = [
    "RESUME_CLOSING_M",
    "line_metrics",
    "measurement_metrics",
    "obstacle_metrics",
]

#: Following has resumed once the robot has driven this far towards the target since the last
#: obstacle left, m.
RESUME_CLOSING_M = 0.2


def line_metrics(traj, lines, mounts, period):
    """``lateral_error_max_m``, ``lateral_error_mean_m``, ``off_line_s`` and ``laps`` of a run
    whose line sensors sit at ``mounts`` (``connectors.Mount``s) on the robot, over the floor
    ``lines`` (``FloorLine``s); rows ``period`` s apart. None values without lines or
    sensors."""
    none = {
        "lateral_error_max_m": None,
        "lateral_error_mean_m": None,
        "off_line_s": None,
        "laps": None,
    }
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
    on_line = np.any(
        [line.covers(px.ravel(), py.ravel()).reshape(px.shape) for line in lines], axis=(0, 1)
    )
    off = int(np.count_nonzero(~on_line))
    track = next((line for line in lines if line.closed), None)
    laps = None
    if track is not None:
        steps = np.diff(track.arc_position(cx, cy))
        length = track.length
        steps = (steps + length / 2) % length - length / 2  # across the start: the short way
        laps = int(abs(float(steps.sum())) // length)
    return {
        "lateral_error_max_m": float(errors.max()),
        "lateral_error_mean_m": float(errors.mean()),
        "off_line_s": off * period,
        "laps": laps,
    }


def obstacle_metrics(traj, events, frame_period):
    """``obstacle_removed_at_s`` (the last furniture removal), ``resumed_after_s`` (from
    then until the robot has driven ``RESUME_CLOSING_M`` towards the target; None if never)
    and ``run_after_removal_s`` (from then to the end of the run, a frame period after its
    last row, as for the loss episodes: a run that ends before a limit has passed cannot show
    that the robot failed to resume within it).

    Only the robot's own motion counts: each step's displacement along the direction from the
    robot to the target at the step's start, summed. A person walking up to a robot that
    stays put brings them closer without the robot resuming anything."""
    removed = [t for _, t, text in events if is_removal_event(text)]
    if not removed:
        return {
            "obstacle_removed_at_s": None,
            "resumed_after_s": None,
            "run_after_removal_s": None,
        }
    t_r = max(removed)
    t = traj["t"]
    after = np.flatnonzero(t >= t_r - 1e-9)
    x, y, tx, ty = (np.asarray(traj[k], float)[after] for k in ("x", "y", "target_x", "target_y"))
    to_x, to_y = (tx - x)[:-1], (ty - y)[:-1]
    step = np.diff(x) * to_x + np.diff(y) * to_y
    # NaN without a target person: never resumed.
    progress = np.cumsum(step / np.maximum(np.hypot(to_x, to_y), 1e-9))
    reached = np.flatnonzero(progress >= RESUME_CLOSING_M)
    resumed = float(t[after[reached[0] + 1]] - t_r) if len(reached) else None
    return {
        "obstacle_removed_at_s": round(t_r, 6),
        "resumed_after_s": resumed,
        "run_after_removal_s": float(t[-1] + frame_period - t_r),
    }


def measurement_metrics(columns, sensors, frames):
    """How often each sensor gave a measurement: ``measured_frames`` (sensor name -> frames
    with one), ``measured_frames_min`` (the fewest; None without sensors), ``silent_sensors``
    (those with none at all) and ``sensor_kinds`` (name -> kind). ``columns`` are the
    trajectory's ``"<sensor>.<measurement>"`` columns (NaN where it had none), ``sensors`` the
    robot's sensors as ``(name, kind)``, ``frames`` the rows done."""
    counts = {}
    for name, _kind in sensors:
        mine = [
            np.asarray(v[:frames], dtype=float)
            for k, v in columns.items()
            if k.startswith(f"{name}.")
        ]
        counts[name] = int(np.any(~np.isnan(mine), axis=0).sum()) if mine else 0
    return {
        "measured_frames": counts,
        "measured_frames_min": min(counts.values()) if counts else None,
        "silent_sensors": [name for name, n in counts.items() if n == 0],
        "sensor_kinds": dict(sensors),
    }
