"""Synthetic frames: deterministic, the right colours, targets where asked."""

import numpy as np
import pytest
from scalar_reference import scalar_match

from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import to_rgb444

COLOURS = [c for c in COLOR_SELECT if c != "none"]


def _matches(frame, sel, **thresholds):
    packed = synthetic.as_rgb444(frame)
    return np.array(
        [[scalar_match(int(p), sel, **thresholds) for p in row] for row in packed], bool
    )


def test_same_seed_same_frame_other_seed_other_frame():
    a = synthetic.blob_frame(32, 24, "green", rng=7)
    b = synthetic.blob_frame(32, 24, "green", rng=7)
    c = synthetic.blob_frame(32, 24, "green", rng=8)
    assert a.shape == (24, 32, 3) and a.dtype == np.uint8
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_default_rng_is_seed_zero():
    assert np.array_equal(synthetic.random_frame(16, 8), synthetic.random_frame(16, 8, 0))


@pytest.mark.parametrize("colour", COLOURS)
@pytest.mark.parametrize("background", ["noise", "dark", "black", "grey"])
def test_target_matches_its_colour_and_background_matches_none(colour, background):
    blob = synthetic.Blob(colour, 20, 11, radius=6)
    frame = synthetic.blob_frame(40, 24, colour, 20, 11, 6, background=background, rng=3)
    mask = blob.mask(40, 24)
    assert mask.sum() > 100
    for other in COLOURS:
        m = _matches(frame, COLOR_SELECT[other])
        assert not m[~mask].any(), f"{background} background matches {other}"
        if other == colour:
            assert m[mask].all()
        else:
            assert not m[mask].any(), f"{colour} target also matches {other}"


def test_wood_distractor_is_red_only_with_a_looser_diff_min():
    wood = synthetic.Blob("wood", 10, 8, size=(6, 4))
    frame = synthetic.blob_frame(
        32, 16, "blue", 25, 8, 3, distractors=[wood], background="black", jitter=0
    )
    mask = wood.mask(32, 16)
    assert mask.sum() == 24
    packed = synthetic.as_rgb444(frame)
    assert set(np.unique(packed[mask])) == {0x942}
    red = COLOR_SELECT["red"]
    assert not _matches(frame, red, diff_min=6).any()
    assert np.array_equal(_matches(frame, red, diff_min=5), mask)


def test_rectangle_blob_covers_exactly_its_pixels():
    frame = synthetic.blob_frame(
        20, 10, "cyan", cx=5, cy=5, size=(4, 2), background="black", jitter=0
    )
    covered = frame.any(axis=2)
    expected = np.zeros((10, 20), bool)
    expected[4:6, 3:7] = True
    assert np.array_equal(covered, expected)


def test_disc_blob_is_symmetric_about_an_integer_centre():
    mask = synthetic.Blob("red", 30, 20, radius=7).mask(61, 41)
    assert np.array_equal(mask, mask[:, ::-1]) and np.array_equal(mask, mask[::-1, :])
    ys, xs = np.nonzero(mask)
    assert xs.mean() == 30 and ys.mean() == 20


def test_as_rgb444_is_to_rgb444():
    frame = synthetic.random_frame(24, 12, rng=5)
    assert np.array_equal(synthetic.as_rgb444(frame), to_rgb444(frame, 24, 12))


def test_speckle_adds_some_matching_pixels_to_the_noise_background():
    frame = synthetic.background_frame(160, 120, "noise", rng=1, speckle=0.05)
    n = int(_matches(frame, COLOR_SELECT["red"]).sum())
    # A uniform random pixel is red with probability 1/16 * P(r - max(g,b) >= 6) ~ 3%.
    assert 0 < n < 0.05 * 160 * 120


def test_lost_scenario_has_a_gap_longer_than_lost_frames():
    sc = synthetic.scenario("lost", 64, 48, lost_frames=5, n_frames=2)
    visible = [s.visible for s in sc.states]
    assert visible == [True] * 2 + [False] * 8 + [True] * 2
    assert len(sc.frames) == len(sc.states)
    assert sc.states[0].cx > 32 > sc.states[-1].cx
    red = COLOR_SELECT["red"]
    for frame, state in zip(sc.frames, sc.states):
        assert _matches(frame, red).any() == state.visible


def test_sweep_moves_right_and_approach_grows():
    sweep = synthetic.scenario_states("sweep", 160, 120, n_frames=5)
    xs = [s.cx for s in sweep]
    assert xs == sorted(xs) and xs[0] < 40 and xs[-1] > 120
    approach = synthetic.scenario_states("approach", 160, 120)
    radii = [s.radius for s in approach]
    assert radii == sorted(radii) and radii[-1] == 60


@pytest.mark.parametrize(
    "call,message",
    [
        (lambda: synthetic.blob_frame(16, 8, "purple"), "unknown colour"),
        (lambda: synthetic.empty_frame(16, 8, "plaid"), "unknown background"),
        (lambda: synthetic.scenario("dance"), "unknown scenario"),
        (lambda: synthetic.Blob("red", 1, 1), "exactly one of"),
        (lambda: synthetic.blob_frame(0, 8), "width must be"),
        (lambda: synthetic.random_frame(8, 8, rng="x"), "rng must be"),
    ],
)
def test_bad_arguments_say_what_is_wrong(call, message):
    with pytest.raises((ValueError, TypeError), match=message):
        call()
