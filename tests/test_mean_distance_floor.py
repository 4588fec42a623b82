"""mean_distance_max_m in a run too short for any robot: the least mean distance a robot at
its top speed could keep (checks.reach) is computed by hand, and a run whose floor is above
the limit leaves the check n/a instead of failing the design."""

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from fpga_robotics.checks.reach import mean_distance_floor, reach
from fpga_robotics.checks.summary import evaluate_checks
from fpga_robotics.sim.world.config import Uncertainty
from fpga_robotics.sim.world.robots import TURTLEBOT2
from fpga_robotics.testing import run


def test_reach_speeds_up_then_cruises():
    # 1 m/s^2 to 0.5 m/s: 0.5 s of ramp (0.125 m), then 0.5 m each second.
    got = reach([0.0, 0.25, 0.5, 1.5], 0.5, 1.0)
    assert got == pytest.approx([0.0, 0.03125, 0.125, 0.625])


def _robot(start=(0.0, 0.0), dps=1146.0, accel_dps2=1637.0, r=0.035, gain=0.0, noise=0.0):
    spec = dataclasses.replace(
        TURTLEBOT2, max_wheel_dps=dps, wheel_accel_dps2=accel_dps2, wheel_radius=r
    )
    return SimpleNamespace(
        spec=spec,
        start=start,
        uncertainty=Uncertainty(motor_gain_error=gain, motor_noise_dps=noise),
    )


def test_floor_is_the_start_distance_less_the_reach():
    # A target standing 3 m away; the robot's wheels: 0.5 m/s, 1 m/s^2.
    r = 0.05
    dps = math.degrees(0.5 / r)
    traj = {
        "t": np.array([0.0, 0.5, 1.5, 10.0]),
        "target_x": np.full(4, 3.0),
        "target_y": np.zeros(4),
        "target_distance": np.full(4, 3.0),  # only its NaNs count
    }
    got = mean_distance_floor(traj, _robot(dps=dps, accel_dps2=math.degrees(1.0 / r), r=r))
    # 3 - (0, 0.125, 0.625, 4.875 -> below 0)
    assert got["mean_distance_floor_m"] == pytest.approx((3.0 + 2.875 + 2.375 + 0.0) / 4)


def test_gain_error_and_noise_widen_the_reach():
    traj = {
        "t": np.array([5.0]),
        "target_x": np.array([10.0]),
        "target_y": np.array([0.0]),
        "target_distance": np.array([10.0]),
    }
    plain = mean_distance_floor(traj, _robot())["mean_distance_floor_m"]
    worse = mean_distance_floor(traj, _robot(gain=0.5, noise=50.0))["mean_distance_floor_m"]
    assert worse < plain


def test_no_target_no_floor():
    traj = {
        "t": np.array([0.0]),
        "target_x": np.array([np.nan]),
        "target_y": np.array([np.nan]),
        "target_distance": np.array([np.nan]),
    }
    assert mean_distance_floor(traj, _robot()) == {"mean_distance_floor_m": None}


@pytest.mark.parametrize(
    "mean, floor, status",
    [(1.0, 1.9, "pass"), (2.0, 1.9, "n/a"), (2.0, 1.5, "fail"), (2.0, None, "fail")],
)
def test_the_check_is_na_only_above_a_floor_above_the_limit(mean, floor, status):
    (result,) = evaluate_checks(
        {"mean_distance_max_m": 1.75}, {"mean_distance_m": mean, "mean_distance_floor_m": floor}
    )
    assert result["status"] == status
    if status == "n/a":
        assert "no robot could have kept it under 1.75 m" in result["text"]


def test_a_one_second_approach_cannot_fail_the_mean_distance():
    # approach: the target stands 2.0 m ahead; a TurtleBot2 (0.7 m/s, 1 m/s^2) closes at most
    # 0.5 * 0.7 + 0.7 * 0.3 = 0.56 m in a second: the mean cannot drop under 1.75 m.
    res = run("approach", overrides=["sim.duration=1"], backend="model")
    s = res.summary
    assert s["mean_distance_m"] > 1.75
    assert 1.75 < s["mean_distance_floor_m"] < s["mean_distance_m"]
    (check,) = [c for c in s["checks"] if c["name"] == "mean_distance_max_m"]
    assert check["status"] == "n/a"
