"""FollowLine's control law (its model, which the gateware equals cycle for cycle: see
test_hw_follow_line.py) in closed loop with a GoPiGo3's differential-drive kinematics on a
closed track whose curves tighten from 1 m to 0.3 m radius: it keeps the robot on the line in
both directions with 1, 2 and 3 sensors; the inverted-polarity variant leaves it."""

import math

import numpy as np
import pytest

from fpga_robotics.hw.sensor_params import FollowLineParams
from fpga_robotics.hw.variants import variant_params
from fpga_robotics.sim.models.follow_line import action, wheel_command
from fpga_robotics.sim.world.robots import GOPIGO3

#: Track: a 3 m x 2 m rounded rectangle, corner radii in driving order (counter-clockwise).
WIDTH_M, HEIGHT_M, RADII = 3.0, 2.0, (1.0, 0.6, 0.4, 0.3)
LINE_WIDTH = 0.025  # m, a strip of tape
SENSOR_FORWARD = 0.06  # m ahead of the wheel axle
#: Lateral offsets of the sensors (m, + = left), left to right.
SENSORS = {3: (0.02, 0.0, -0.02), 2: (0.02, -0.02), 1: (0.0,)}
DT = 1 / 240  # the closed loop's physics step


def track_points(step=0.005):
    """Points every ``step`` m along the track's centreline, counter-clockwise from the
    middle of the bottom side."""
    X, Y, r = WIDTH_M, HEIGHT_M, RADII
    sides = [
        ((r[3], 0), (X - r[0], 0)),
        ((X, r[0]), (X, Y - r[1])),
        ((X - r[1], Y), (r[2], Y)),
        ((0, Y - r[2]), (0, r[3])),
    ]
    corners = [
        (X - r[0], r[0], r[0], -90),
        (X - r[1], Y - r[1], r[1], 0),
        (r[2], Y - r[2], r[2], 90),
        (r[3], r[3], r[3], 180),
    ]
    pts = []
    for ((x0, y0), (x1, y1)), (cx, cy, radius, a0) in zip(sides, corners):
        n = max(2, int(math.hypot(x1 - x0, y1 - y0) / step))
        t = np.arange(n) / n
        pts.append(np.stack([x0 + (x1 - x0) * t, y0 + (y1 - y0) * t], axis=1))
        n = max(2, int(radius * math.pi / 2 / step))
        a = np.radians(a0 + 90 * np.arange(n) / n)
        pts.append(np.stack([cx + radius * np.cos(a), cy + radius * np.sin(a)], axis=1))
    pts = np.concatenate(pts)
    return np.roll(pts, -int(np.argmin(np.hypot(pts[:, 0] - X / 2, pts[:, 1]))), axis=0)


def drive(params, *, clockwise=False, seconds=66.0):
    """Run the law on the track; returns (laps, largest distance of the axle's centre from
    the centreline (m))."""
    track = track_points()
    if clockwise:
        track = track[::-1]
    arc = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(track, axis=0).T))])
    length = arc[-1] + float(np.hypot(*(track[0] - track[-1])))
    x, y = track[0]
    heading = math.atan2(*(track[1] - track[0])[::-1])
    left = right = 0.0  # wheel speeds, DPS, rate-limited as the GoPiGo3's
    side, travelled, last, worst = "left", 0.0, 0, 0.0
    offsets = SENSORS[params.n_sensors]
    for _ in range(int(seconds / DT)):
        c, s = math.cos(heading), math.sin(heading)
        seen = []
        for o in offsets:
            px, py = x + SENSOR_FORWARD * c - o * s, y + SENSOR_FORWARD * s + o * c
            on = np.min(np.hypot(track[:, 0] - px, track[:, 1] - py)) <= LINE_WIDTH / 2
            # The KY-033 is high over the line; the design reads it by its polarity.
            seen.append(int(on) if params.active_high else 1 - int(on))
        name, side = action(params, seen, side)
        want_left, want_right = wheel_command(params, name)
        ramp = GOPIGO3.wheel_accel_dps2 * DT
        left += float(np.clip(want_left - left, -ramp, ramp))
        right += float(np.clip(want_right - right, -ramp, ramp))
        v_left = math.radians(left) * GOPIGO3.wheel_radius
        v_right = math.radians(right) * GOPIGO3.wheel_radius
        v = (v_left + v_right) / 2
        x, y = x + v * c * DT, y + v * s * DT
        heading += (v_right - v_left) / GOPIGO3.wheel_separation * DT
        distances = np.hypot(track[:, 0] - x, track[:, 1] - y)
        nearest = int(np.argmin(distances))
        worst = max(worst, float(distances[nearest]))
        step = arc[nearest] - arc[last]
        travelled += step - length * round(step / length)  # across the start, either way
        last = nearest
    return travelled / length, worst


@pytest.mark.parametrize("n", [3, 2, 1])
@pytest.mark.parametrize("clockwise", [False, True])
def test_law_follows_a_track_of_tightening_curves(n, clockwise):
    laps, worst = drive(FollowLineParams(n_sensors=n), clockwise=clockwise)
    # The track is 10 - (2 - pi / 2) * 2.3 = 9.01 m long; 66 s at 0.145 m/s is 9.6 m, 1.06
    # laps with no time lost turning. A whole lap passes every corner.
    assert laps > 1.0
    # Straddling or on the line: the axle stays within the line's width of the centreline;
    # one sensor follows an edge, half a width off.
    assert worst < (LINE_WIDTH if n > 1 else 1.5 * LINE_WIDTH)


def test_inverted_polarity_variant_leaves_the_line():
    laps, worst = drive(variant_params("line_inverted_polarity"), seconds=30.0)
    assert worst > 0.3 and laps < 0.5
