"""The sensor designs' metrics against hand-computed values."""

import numpy as np
import pytest

from fpga_robotics.checks.registry import sensor_check
from fpga_robotics.checks.sensor_metrics import RESUME_CLOSING_M, obstacle_metrics


def _traj(t, d):
    return {"t": np.asarray(t, float), "target_distance": np.asarray(d, float)}


def test_resumed_after_is_the_first_row_the_robot_is_closer_by_the_margin():
    # Removed at 1.0 s; distance 2.0 m then; 1.75 m (0.25 closer) first at 1.6 s.
    t = [0.0, 0.5, 1.0, 1.2, 1.4, 1.6, 1.8]
    d = [2.5, 2.0, 2.0, 2.0, 1.9, 1.75, 1.5]
    events = [(3, 1.0, "furniture 'box' removed"), (0, 0.0, "target found")]
    m = obstacle_metrics(_traj(t, d), events)
    assert m["obstacle_removed_at_s"] == 1.0
    assert 1.9 > 2.0 - RESUME_CLOSING_M  # 1.4 s is not enough
    assert m["resumed_after_s"] == pytest.approx(0.6)
    assert sensor_check("resumes_within_s", 1.0, m)[0] is True
    assert sensor_check("resumes_within_s", 0.5, m)[0] is False


def test_never_resumed_and_never_removed_both_fail_with_a_reason():
    m = obstacle_metrics(_traj([0, 1, 2], [2.0, 2.0, 1.95]), [(1, 1.0, "furniture 'b' removed")])
    assert m["resumed_after_s"] is None
    ok, text = sensor_check("resumes_within_s", 5.0, m)
    assert not ok and "never closed" in text
    m = obstacle_metrics(_traj([0, 1], [2.0, 1.0]), [])
    ok, text = sensor_check("resumes_within_s", 5.0, m)
    assert not ok and "no furniture was removed" in text


def _rows(xs, ys, headings):
    return {
        "t": np.arange(len(xs)) * 0.1,
        "x": np.asarray(xs, float),
        "y": np.asarray(ys, float),
        "heading": np.asarray(headings, float),
    }


def test_lateral_error_and_time_off_a_straight_line_by_hand():
    from fpga_robotics.checks.sensor_metrics import line_metrics
    from fpga_robotics.loop.connectors import Mount
    from fpga_robotics.sim.world.markings import FloorLine

    tape = FloorLine("tape", ((0.0, 1.0), (4.0, 1.0)), 0.02)
    # One sensor 0.1 m ahead of the robot's centre, the robot heading +x: the sensor's
    # offset from y = 1 is the robot's. Offsets 0, 5 mm (on the 20 mm tape), 30 mm (off it).
    m = line_metrics(
        _rows([1.0, 1.1, 1.2], [1.0, 1.005, 0.97], [0.0] * 3), [tape], [Mount(forward=0.1)], 0.1
    )
    assert m["lateral_error_max_m"] == pytest.approx(0.03)
    assert m["lateral_error_mean_m"] == pytest.approx(round(0.035 / 3, 4))
    assert m["off_line_s"] == pytest.approx(0.1)  # one row of 0.1 s off the tape
    assert m["laps"] is None  # an open line has no laps
    # Two sensors 10 mm either side: their centre is the robot's line; the one row with the
    # robot 30 mm off still has no sensor on the tape, the 15 mm row has one.
    m = line_metrics(
        _rows([1.0, 1.1], [1.015, 0.97], [0.0] * 2),
        [tape],
        [Mount(left=0.01), Mount(left=-0.01)],
        0.1,
    )
    assert m["off_line_s"] == pytest.approx(0.1)
    assert m["lateral_error_max_m"] == pytest.approx(0.03)


def test_laps_count_the_net_progress_around_a_closed_line():
    from fpga_robotics.checks.sensor_metrics import line_metrics
    from fpga_robotics.loop.connectors import Mount
    from fpga_robotics.sim.world.markings import FloorLine

    square = FloorLine("sq", ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)), 0.02, closed=True)
    # Round the 4 m square one and a half times counter-clockwise, 0.25 m a row.
    s = np.arange(0, 6.0 + 1e-9, 0.25)
    side, along = (s // 1) % 4, s % 1
    xs = np.choose(side.astype(int), [along, np.ones_like(s), 1 - along, np.zeros_like(s)])
    ys = np.choose(side.astype(int), [np.zeros_like(s), along, np.ones_like(s), 1 - along])
    m = line_metrics(_rows(xs, ys, np.zeros_like(s)), [square], [Mount()], 0.1)
    assert m["laps"] == 1 and m["off_line_s"] == 0 and m["lateral_error_max_m"] == 0
    # The same way back: still one whole lap (net progress, either direction).
    m = line_metrics(_rows(xs[::-1], ys[::-1], np.zeros_like(s)), [square], [Mount()], 0.1)
    assert m["laps"] == 1
