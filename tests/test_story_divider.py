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
        "centroid away from the target in 33% of the frames with the target "
        "found and in view (limit <= 5%)"
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
