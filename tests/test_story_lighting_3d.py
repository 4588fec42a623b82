"""The lighting story in 3D (docs/render3d.md): the light comes from behind the person in
red, so the robot sees the suit's shadow side; at dusk its red drops under the default
``diff_min = 6`` and the person is lost (``found_min_fraction`` fails); the scenario's
``diff_min = 3`` keeps it."""

import pytest
from render3d_scenes import mujoco_missing

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

pytestmark = [pytest.mark.stories, mujoco_missing]

SHORT = "sim.duration=16"  # dusk falls from 0 to 8 s and holds


def _failed(r):
    return {c["name"] for c in r.summary["checks"] if not c["passed"]}


def test_the_shadow_side_drops_out_of_the_default_filter_at_dusk():
    r = run_scenario(load_scenario("lighting_3d", [SHORT, "design.diff_min=6"]), backend="model")
    assert "found_min_fraction" in _failed(r)


def test_a_lower_threshold_keeps_the_shadow_side():
    r = run_scenario(load_scenario("lighting_3d", [SHORT]), backend="model")
    assert r.summary["verdict"] == "pass", _failed(r)
    assert r.summary["found_fraction"] == 1.0
