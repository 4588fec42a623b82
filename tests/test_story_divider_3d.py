"""Story (a) in 3D (docs/render3d.md): a warm spot lamp on the divider's wood grain lifts it
into a red filter tuned on the raster's flat frames. The default ``diff_min = 6`` takes the
lit grain for red and the robot turns to the divider (``max_off_target_fraction`` fails); the
scenario's ``diff_min = 8`` rejects it and tracks the person."""

import pytest
from render3d_scenes import mujoco_missing

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

pytestmark = [pytest.mark.stories, mujoco_missing]

SHORT = "sim.duration=10"  # the robot has turned to the wood well before


def _failed(r):
    return {c["name"] for c in r.summary["checks"] if not c["passed"]}


def test_the_filter_tuned_on_flat_frames_steers_to_the_lit_wood():
    r = run_scenario(load_scenario("divider_3d", [SHORT, "design.diff_min=6"]), backend="model")
    assert "max_off_target_fraction" in _failed(r)
    assert r.summary["off_target_fraction"] > 0.3


def test_the_tighter_filter_tracks_the_person_under_the_lamp():
    r = run_scenario(load_scenario("divider_3d", [SHORT]), backend="model")
    # (Its full 25 s run passes every check: tests/test_scenario_long_runs.py.)
    assert not {"max_off_target_fraction", "target_in_view_min_fraction"} & _failed(r)
    assert r.summary["off_target_fraction"] == 0.0
