"""Story (d) of the paper (docs/stories.md): a centroid off-centre because a signal had too
narrow a bit range. The centring check ``mean_centroid_error_max_px``: in ``approach`` the
person stands on the robot's axis, so the design's centroid must be at the image centre.
Here the check on a hand-computed centroid; the gateware knob that narrows the range
(``design.sx_bits``) and its run are in tests/test_story_narrow_centroid.py."""

import numpy as np
import pytest

from fpga_robotics.checks.summary import compute_metrics, evaluate_checks
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import available_backends


def _metrics(centroid, column=80.0, n=30):
    traj = {
        "t": np.arange(n) / 30,
        "x": np.zeros(n),
        "y": np.zeros(n),
        "found": np.ones(n, bool),
        "target_distance": np.ones(n),
        "target_in_view": np.ones(n, bool),
        "centroid_x": np.full(n, centroid),
        "target_column": np.full(n, column),
    }
    return compute_metrics(traj, [], {}, 1 / 30, width=160)


def test_a_sum_of_x_wrapped_in_too_few_bits_fails_the_centring_check():
    # The person fills columns 60..99 (centred on 80) over 50 rows: 2000 pixels whose columns
    # add up to 50 * (60 + ... + 99) = 50 * 3180 = 159000; the centroid is 159000 // 2000 = 79.
    cols = np.tile(np.arange(60, 100), 50)
    count, sum_x = len(cols), int(cols.sum())
    assert (count, sum_x, sum_x // count) == (2000, 159000, 79)
    # A 17-bit sum wraps at 131072: 27928 // 2000 = 13, far left of the centre.
    narrow = (sum_x % (1 << 17)) // count
    assert narrow == 13
    good, bad = _metrics(sum_x // count), _metrics(narrow)
    assert good["mean_centroid_error_px"] == 1.0 and bad["mean_centroid_error_px"] == 67.0
    assert evaluate_checks({"mean_centroid_error_max_px": 2.0}, good)[0]["passed"]
    (c,) = evaluate_checks({"mean_centroid_error_max_px": 2.0}, bad)
    assert not c["passed"]
    assert c["text"] == (
        "centroid 67.00 px from the target's image column on average (limit <= 2.0 px)"
    )


@pytest.mark.stories
@pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no C++ compiler")
def test_story_d_the_default_design_centres_a_target_straight_ahead():
    r = run_scenario(load_scenario("approach"), backend="cxxrtl")
    (c,) = [c for c in r.summary["checks"] if c["name"] == "mean_centroid_error_max_px"]
    assert c["passed"] and r.summary["mean_centroid_error_px"] < 1.0
    # Straight ahead: the target's column is the image centre to within a pixel.
    assert np.nanmax(np.abs(r.trajectory["target_column"] - 80)) < 1.0
