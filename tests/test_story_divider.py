"""Story (a) of the paper (docs/stories.md): a wooden divider taken for the red target. The
check ``max_off_target_fraction`` compares the design's centroid with the target's image
column, ``W/2 - f tan(bearing)`` with ``f = (W/2) / tan(hfov/2)`` (sim/camera/raster.py)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fpga_robotics.checks.summary import compute_metrics, evaluate_checks
from fpga_robotics.loop.compressed import target_column
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import available_backends

CAM = SimpleNamespace(width=160, hfov=math.radians(60))
POSE = SimpleNamespace(x=1.0, y=2.0, heading=math.radians(90))  # looking along +y


def test_target_column_straight_ahead_left_and_behind():
    assert target_column(POSE, CAM, 1.0, 5.0) == pytest.approx(80.0)
    # 15 degrees to the left (heading + 15 deg): f = 80 / tan 30 = 138.56, tan 15 = 0.2679,
    # column 80 - 37.13 = 42.87 (the left of the image).
    b = math.radians(105)
    col = target_column(POSE, CAM, 1.0 + 2 * math.cos(b), 2.0 + 2 * math.sin(b))
    assert col == pytest.approx(80 - 80 / math.tan(math.radians(30)) * math.tan(math.radians(15)))
    assert col == pytest.approx(42.87, abs=0.01)
    assert math.isnan(target_column(POSE, CAM, 1.0, 0.0))  # behind
    assert math.isnan(target_column(POSE, CAM, 3.0, 2.5))  # 76 deg to the right: outside 30


def _traj(centroid, column, found):
    n = len(centroid)
    return {
        "t": np.arange(n) / 30,
        "x": np.zeros(n),
        "y": np.zeros(n),
        "found": np.asarray(found),
        "target_distance": np.ones(n),
        "target_in_view": np.ones(n, bool),
        "centroid_x": np.asarray(centroid),
        "target_column": np.asarray(column, float),
    }


def test_off_target_fraction_counts_frames_found_with_the_target_in_view():
    # Tolerance 160 / 8 = 20 px. Frames: error 0, 21 (off), 19, 50 (off, but not found),
    # target centre out of view (NaN): 1 of 3 counted frames is off target.
    m = compute_metrics(
        _traj([80, 101, 99, 130, 10], [80, 80, 80, 80, math.nan], [True, True, True, False, True]),
        [],
        {},
        1 / 30,
        width=160,
    )
    assert m["off_target_fraction"] == 1 / 3
    assert m["mean_centroid_error_px"] == pytest.approx(40 / 3)
    (c,) = evaluate_checks({"max_off_target_fraction": 0.05}, m)
    assert not c["passed"]
    assert c["text"] == (
        "centroid away from the target, or the target out of view, in 33% of the frames found "
        "(limit <= 5%)"
    )


def test_frames_found_with_the_target_out_of_view_are_away():
    """A design that reports found while none of the target is in view has taken something
    else for it (a red passer-by it follows while the target, in blue, is behind): those
    frames count as away, so a design that locks on such a decoy fails instead of being n/a."""
    # Two frames found on the target (error 0), two found with the target out of view: 2 of 4.
    tr = _traj([80, 80, 40, 120], [80, 80, math.nan, math.nan], [True] * 4)
    tr["target_in_view"] = np.array([True, True, False, False])
    m = compute_metrics(tr, [], {}, 1 / 30, width=160)
    assert m["off_target_fraction"] == 0.5 and m["mean_centroid_error_px"] == 0.0
    # Found only on the decoy: all away; the mean error has no frame to judge.
    tr["target_in_view"][:] = False
    tr["target_column"][:] = math.nan
    m = compute_metrics(tr, [], {}, 1 / 30, width=160)
    assert m["off_target_fraction"] == 1.0 and m["mean_centroid_error_px"] is None
    off, mean = evaluate_checks(
        {"max_off_target_fraction": 0.05, "mean_centroid_error_max_px": 3.0}, m
    )
    assert off["status"] == "fail" and mean["status"] == "n/a"
    # Never found: nothing to judge.
    tr["found"][:] = False
    m = compute_metrics(tr, [], {}, 1 / 30, width=160)
    (off,) = evaluate_checks({"max_off_target_fraction": 0.05}, m)
    assert off["status"] == "n/a" and off["reason"] == (
        "the design never reported the target found with its centre in view, nor with it out "
        "of view"
    )


def _failed(r):
    return {c["name"] for c in r.summary["checks"] if not c["passed"]}


CXXRTL = pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no C++ compiler")


@pytest.mark.stories
@CXXRTL
def test_story_a_a_loose_filter_steers_to_the_divider():
    r = run_scenario(load_scenario("divider", ["design.diff_min=5"]), backend="cxxrtl")
    assert {"max_off_target_fraction", "target_in_view_min_fraction"} <= _failed(r)
    assert r.summary["off_target_fraction"] > 0.5


@pytest.mark.stories
@CXXRTL
def test_story_a_the_default_filter_tracks_the_person():
    r = run_scenario(load_scenario("divider"), backend="cxxrtl")
    assert r.summary["verdict"] == "pass", _failed(r)
    assert r.summary["off_target_fraction"] == 0.0
    assert r.summary["mean_centroid_error_px"] < 2.0
