"""Story (d) of the paper (docs/stories.md), with the buggy gateware: a centroid off-centre
because a signal had too narrow a bit range. ``design.sx_bits`` narrows ``SX``, the column sum
the centroid ``SX // N`` is computed from; in 17 bits it wraps at 131072, which a person
straight ahead at 160x120 exceeds (a centred blob wraps from 1639 pixels: 80 * 1639 > 131072).
In ``approach`` the person stands on the robot's axis: the default design's centroid sits at
the image centre and passes ``mean_centroid_error_max_px``; the narrow one's is far left of it
and fails."""

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import available_backends, get_backend
from fpga_robotics.sim.camera import synthetic

NARROW = "design.sx_bits=17"

needs_cxxrtl = pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no C++ compiler")


def _centring(result):
    (c,) = [c for c in result.summary["checks"] if c["name"] == "mean_centroid_error_max_px"]
    return c


def test_the_scenario_key_narrows_sx():
    assert load_scenario("approach").params.sx_bits is None
    p = load_scenario("approach", [NARROW]).params
    assert (p.sx_bits, p.sum_x_bits, p.full_sum_x_bits) == (17, 17, 22)
    assert p.replace(sx_bits=None) == load_scenario("approach").params


@needs_cxxrtl
def test_the_narrow_gateware_equals_the_model_on_an_approaching_target():
    # A centred target growing from 7 to 60 pixels in radius: SX wraps in the later frames.
    params = FollowTargetParams(sx_bits=17)
    rng = np.random.default_rng(5)
    frames = synthetic.scenario("approach", n_frames=8, rng=rng).frames
    frames.append(synthetic.blob_frame(160, 120, "red", cx=120, radius=40, rng=rng))
    with get_backend("model", params) as m:
        ref = [m.process_frame(f, "red") for f in frames]
    with get_backend("cxxrtl", params) as b:
        got = [b.process_frame(f, "red") for f in frames]
    assert [r.outputs() for r in got] == [r.outputs() for r in ref]
    with get_backend("model", FollowTargetParams()) as m:
        full = [m.process_frame(f, "red") for f in frames]
    # The early frames are below the wrap and centred; the later ones are off-centre.
    assert full[0].centroid_x == ref[0].centroid_x
    assert all(abs(r.centroid_x - 80) <= 1 for r in full[:8])
    assert any(abs(r.centroid_x - 80) > 20 for r in ref[:8])


@pytest.mark.stories
@needs_cxxrtl
def test_story_d_a_too_narrow_sx_puts_the_centroid_off_centre():
    good = run_scenario(load_scenario("approach"), backend="cxxrtl")
    c = _centring(good)
    assert c["passed"] and good.summary["mean_centroid_error_px"] < 1.0
    bad = run_scenario(load_scenario("approach", [NARROW]), backend="cxxrtl")
    c = _centring(bad)
    assert not c["passed"]
    assert bad.summary["mean_centroid_error_px"] > 40.0
    assert c["text"].startswith("centroid ") and c["text"].endswith(
        "px from the target's image column on average (limit <= 2.0 px)"
    )
    # The first frame, before the robot moves: the person straight ahead (image column 80),
    # the full-width centroid at 79, the wrapped one far left of the centre.
    t0, t1 = good.trajectory, bad.trajectory
    assert abs(t0["target_column"][0] - 80) < 1.0 and abs(t1["target_column"][0] - 80) < 1.0
    assert t0["centroid_x"][0] == 79 and t1["centroid_x"][0] < 40
