"""The corridor scenario: CorridorFollow keeps clear of the walls and the cabinet on its
LIDAR's stream, and the mirrored-bearing variant fails its named check (it drives into a
wall). At a 1 MHz clock (the LIDAR's 2000 samples/s are 500 edges apart) to keep it short."""

import pytest

from fpga_robotics.loop import run_scenario
from fpga_robotics.scenario import load_scenario

FAST = ["sim.clock_hz=1000000"]


def _failed(result):
    return [c["name"] for c in result.summary["checks"] if c["passed"] is False]


@pytest.mark.slow
def test_the_corridor_passes_with_the_default_design():
    r = run_scenario(load_scenario("corridor", FAST), backend="cxxrtl")
    assert r.passed, r.summary["checks"]
    # It drove down the corridor past the cabinet (x 2.2 .. 2.8), not round in circles.
    assert r.trajectory["x"][-1] > 3.0
    # Every frame after the first revolution (0.18 s) has the LIDAR's nearest return, the
    # nearest a wall or the cabinet at most half the 1 m corridor away (plus the noise).
    nearest = r.trajectory["lidar.nearest_m"][10:]
    assert (nearest > 0.1).all() and (nearest < 0.55).all()


@pytest.mark.slow
def test_the_mirrored_variant_fails_max_wall_collisions():
    s = load_scenario(
        "corridor", [*FAST, "sim.duration=8", "design.variant=lidar_bearing_mirrored"]
    )
    assert _failed(run_scenario(s, backend="cxxrtl")) == ["max_wall_collisions"]


def test_the_lidar_campaign_runs_both_bindings_over_seeds():
    from fpga_robotics.sweep import load_campaign_file

    campaign = load_campaign_file("lidar")
    runs = sorted((r.scenario, r.seed) for r in campaign.runs)
    assert runs == [(s, seed) for s in ("corridor", "corridor_uart") for seed in range(5)]
