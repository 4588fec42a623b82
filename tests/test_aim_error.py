"""max_mean_aim_error_deg: the camera's mean bearing error to the target, checked on hand-made
geometry, and on follow_person, where a design that never steers passed every other check."""

import numpy as np
import pytest

from fpga_robotics.checks.summary import _mean_aim_error
from fpga_robotics.testing import run


def test_mean_aim_error_is_the_unsigned_bearing_in_and_out_of_view():
    # Robot at the origin facing +x; the target at 45 deg left, straight ahead, 90 deg right,
    # then behind (180 deg): a frame without a target (NaN) is left out.
    traj = {
        "x": np.zeros(5),
        "y": np.zeros(5),
        "heading": np.zeros(5),
        "target_x": np.array([1.0, 2.0, 0.0, -1.0, np.nan]),
        "target_y": np.array([1.0, 0.0, -3.0, 0.0, np.nan]),
    }
    assert _mean_aim_error(traj) == pytest.approx((45 + 0 + 90 + 180) / 4)


def test_no_target_no_aim_error():
    nan = np.array([np.nan])
    traj = {
        "x": np.zeros(1),
        "y": np.zeros(1),
        "heading": np.zeros(1),
        "target_x": nan,
        "target_y": nan,
    }
    assert _mean_aim_error(traj) is None


def _aim(summary):
    (c,) = [c for c in summary["checks"] if c["name"] == "max_mean_aim_error_deg"]
    return c


def test_follow_person_fails_a_design_that_never_steers_and_passes_the_default():
    good = run("follow_person", backend="model").summary
    assert good["verdict"] == "pass" and _aim(good)["status"] == "pass"
    assert good["mean_aim_error_deg"] < 2.5
    # (3 * e) >> 9 turns by 0 for every column error e the image has: the person drifts
    # off-centre and out of view and back while the robot drives on its proximity law.
    lazy = run("follow_person", backend="model", overrides=["design.kp_shift=9"]).summary
    failed = [c["name"] for c in lazy["checks"] if c["status"] == "fail"]
    assert failed == ["max_mean_aim_error_deg"]
    assert lazy["mean_aim_error_deg"] > 10
