"""The terrain scenarios (docs/scenarios.md, "Terrain"): ``ramp`` and ``slippery`` pass with
the default design and fail, on the named check, with the robot the scenario's comment names
(gravity against traction: ``m g sin(theta)`` against ``friction * traction_force``)."""

import math

import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import available_backends
from fpga_robotics.sim.world.robots import G

CXXRTL = pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no C++ compiler")


def _failed(r):
    return {c["name"] for c in r.summary["checks"] if c["passed"] is False}


def test_the_scenarios_numbers_are_on_the_right_side_of_the_limit():
    ramp = load_scenario("ramp")
    (patch,) = ramp.world["room"]["terrain"]
    theta = math.radians(patch["slope_deg"])
    assert 6.3 * G * math.sin(theta) < 12.6 < 9.0 * G * math.sin(theta)  # holds, then not
    slippery = load_scenario("slippery")
    (wet,) = slippery.world["room"]["terrain"]
    pull = 6.3 * G * math.sin(math.radians(wet["slope_deg"]))
    assert 6.0 * wet["friction"] < pull < 12.6 * wet["friction"]


@pytest.mark.stories
@CXXRTL
def test_ramp_the_default_robot_climbs_a_heavier_one_cannot():
    ok = run_scenario(load_scenario("ramp"), backend="cxxrtl")
    assert ok.passed, _failed(ok)
    heavy = run_scenario(load_scenario("ramp", ["robot.mass=9"]), backend="cxxrtl")
    assert _failed(heavy) == {"mean_distance_max_m"}
    # It never got far up: the robot stays near the foot of the ramp (x = 2).
    assert heavy.trajectory["x"].max() < ok.trajectory["x"].max() - 0.5
    assert any(t.startswith("terrain: on 'ramp'") for _, _, t in ok.events)


@pytest.mark.stories
@CXXRTL
def test_slippery_weak_grip_slides_into_the_wall():
    ok = run_scenario(load_scenario("slippery"), backend="cxxrtl")
    assert ok.passed, _failed(ok)
    weak = run_scenario(load_scenario("slippery", ["robot.traction_force=6"]), backend="cxxrtl")
    assert "max_wall_collisions" in _failed(weak)
    # Sideways, downhill (towards y = 0), not forwards.
    assert weak.trajectory["y"].min() < ok.trajectory["y"].min() - 1.0
