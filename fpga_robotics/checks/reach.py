"""The least mean distance to the target any robot could have kept in a run: from its start,
at its top speed and acceleration, towards where the target was in each frame. A run too
short for even that robot to bring the mean under ``mean_distance_max_m`` leaves the check
nothing to judge (a shorter ``--duration`` than the limit was chosen for)."""

import math

import numpy as np

__all__ = ["mean_distance_floor", "reach"]

#: The wheel speed noise counted on top of the top speed, in standard deviations.
_NOISE_SIGMAS = 3.0


def reach(t, speed, accel):
    """How far a robot starting at rest can get in ``t`` s (array), speeding up at ``accel``
    (m/s^2) to at most ``speed`` (m/s)."""
    t = np.asarray(t, dtype=float)
    t_top = speed / accel
    return np.where(t < t_top, 0.5 * accel * t**2, 0.5 * speed * t_top + speed * (t - t_top))


def _top_speed_accel(robot):
    """The fastest the robot's centre can move, m/s, and speed up, m/s^2: the spec's
    ``max_speed`` and ``motor_accel`` at the largest gain error, plus three standard
    deviations of the wheel speed noise."""
    spec, u = robot.spec, robot.uncertainty
    gain = 1.0 + u.motor_gain_error
    noise = math.radians(_NOISE_SIGMAS * u.motor_noise_dps) * spec.wheel_radius
    return spec.max_speed * gain + noise, spec.motor_accel * gain


def mean_distance_floor(traj, robot):
    """``mean_distance_floor_m``: over the frames with a target (those ``mean_distance_m``
    averages), the mean of the target's distance from the robot's start less the robot's
    ``reach`` by then (never below 0); None without a target. No robot of this ``robot``
    (``sim.world.config.RobotConfig``) driving itself gets a lower mean (a push by a person
    or a slope downhill are not counted)."""
    dist = np.asarray(traj["target_distance"], dtype=float)
    valid = ~np.isnan(dist)
    if not valid.any():
        return {"mean_distance_floor_m": None}
    sx, sy = robot.start
    t = np.asarray(traj["t"], dtype=float)[valid]
    d0 = np.hypot(
        np.asarray(traj["target_x"])[valid] - sx, np.asarray(traj["target_y"])[valid] - sy
    )
    speed, accel = _top_speed_accel(robot)
    floor = np.maximum(0.0, d0 - reach(t, speed, accel))
    return {"mean_distance_floor_m": float(floor.mean())}
