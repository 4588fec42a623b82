"""Each pass criterion at exactly its limit: a limit is inclusive ("at most", "at least"),
as docs/running.md states, so a metric equal to it passes and the next value out fails."""

import pytest

from fpga_robotics.checks.summary import evaluate_checks

#: Metrics of a run that passes everything comfortably.
GOOD = {
    "acquired_at_s": 0.5,
    "mean_distance_m": 1.0,
    "min_distance_m": 1.0,
    "collisions": {"person": 0, "wall": 0, "furniture": 0},
    "target_in_view_fraction": 1.0,
    "found_after_acquisition_fraction": 1.0,
}


def verdict_of(check, limit, **metrics):
    (result,) = evaluate_checks({check: limit}, {**GOOD, **metrics})
    return result["passed"]


@pytest.mark.parametrize(
    "check, limit, key, at_limit, beyond",
    [
        ("acquired_within_s", 1.0, "acquired_at_s", 1.0, 1.0 + 1e-9),
        ("mean_distance_max_m", 3.5, "mean_distance_m", 3.5, 3.5 + 1e-9),
        ("min_distance_min_m", 0.6, "min_distance_m", 0.6, 0.6 - 1e-9),
        ("target_in_view_min_fraction", 0.9, "target_in_view_fraction", 0.9, 0.9 - 1e-9),
        ("found_min_fraction", 0.9, "found_after_acquisition_fraction", 0.9, 0.9 - 1e-9),
    ],
)
def test_a_metric_on_the_limit_passes_and_just_beyond_fails(check, limit, key, at_limit, beyond):
    assert verdict_of(check, limit, **{key: at_limit})
    assert not verdict_of(check, limit, **{key: beyond})


@pytest.mark.parametrize("kind", ["person", "wall", "furniture"])
def test_collision_limits_are_inclusive(kind):
    counts = dict(GOOD["collisions"])
    counts[kind] = 2
    assert verdict_of(f"max_{kind}_collisions", 2, collisions=counts)
    assert not verdict_of(f"max_{kind}_collisions", 1, collisions=counts)
