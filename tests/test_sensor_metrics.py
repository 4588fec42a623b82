"""The sensor designs' metrics against hand-computed values."""


import numpy as np
import pytest

from fpga_robotics.sensor_metrics import RESUME_CLOSING_M, obstacle_metrics, sensor_check


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
