"""The mutation campaign's far_green run: a green target followed from 8 m, so that the approach
law's far proximity levels and the colour filter's green rule are exercised (the campaign's
other scenarios reach levels 3 to 6 only, with red targets)."""

import numpy as np
import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sweep.campaign import load_campaign, read_campaign_file


def _far_green_spec():
    data, _ = read_campaign_file("mutation")
    (spec,) = [r for r in load_campaign(data).runs if r.scenario.endswith("far_green.toml")]
    return spec


@pytest.mark.slow
def test_far_green_drives_through_every_forward_level_and_passes():
    spec = _far_green_spec()
    items = [*spec.set_items(), f"sim.duration={float(spec.duration)!r}"]
    result = run_scenario(load_scenario(spec.scenario, items), seed=0, backend="model")
    traj, summary = result.trajectory, result.summary
    found = np.asarray(traj["found"], bool)
    levels = set(np.asarray(traj["proximity"])[found].tolist())
    assert {1, 2, 3, 4, 5, 6} <= levels
    assert set(np.asarray(traj["color_sel"]).tolist()) == {0b010}  # green
    assert summary["approach_speed_violation_fraction"] == 0
    assert summary["stop_overshoot_m"] is not None  # it comes near enough to be judged
    assert summary["verdict"] == "pass"
