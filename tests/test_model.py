"""Golden model against independent expectations: scalar formulas, loops, hand-computed values."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scalar_reference import loop_track, scalar_match

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import FrameError
from fpga_robotics.sim.models.follow_target import (
    FollowTargetModel,
    MotorModel,
    TrackerResult,
    centroid_leds,
    color_match,
    filter_frame,
    is_found,
    table_command,
    track_frame,
)

# A 64x64 frame holds each of the 4096 RGB444 values exactly once.
ALL_PIXELS = np.arange(4096, dtype=np.uint16).reshape(64, 64)


def _all_pixel_params(**thresholds):
    return FollowTargetParams(width=64, height=64, margin_x=0, margin_y=0, **thresholds)


def _expected_match(sel, **thresholds):
    flat = [scalar_match(p, sel, **thresholds) for p in range(4096)]
    return np.array(flat, bool).reshape(64, 64)


# Colour filter ------------------------------------------------------------------------------


@pytest.mark.parametrize("sel", range(8))
def test_filter_at_default_thresholds_matches_the_scalar_formula_for_every_pixel(sel):
    params = _all_pixel_params()
    expected = _expected_match(sel)
    assert np.array_equal(color_match(ALL_PIXELS, sel, params), expected)
    filtered = filter_frame(ALL_PIXELS, sel, params)
    assert filtered.dtype == np.uint16
    assert np.array_equal(filtered, np.where(expected, ALL_PIXELS, 0))


@settings(max_examples=25, deadline=None)
@given(
    sel=st.integers(0, 7),
    diff_min=st.integers(0, 15),
    similar_max=st.integers(0, 15),
    white_min=st.integers(0, 15),
)
def test_filter_matches_the_scalar_formula_at_any_thresholds(sel, diff_min, similar_max, white_min):
    thresholds = {"diff_min": diff_min, "similar_max": similar_max, "white_min": white_min}
    params = _all_pixel_params(**thresholds)
    assert np.array_equal(color_match(ALL_PIXELS, sel, params), _expected_match(sel, **thresholds))


@pytest.mark.parametrize(
    "pixel,colour,diff_min,matches",
    [
        (0xF00, "red", 15, True),  # 15 - 0 >= 15
        (0x0F0, "red", 0, False),  # 0 - 15 is negative: never a match, even at diff_min 0
        (0x000, "red", 0, True),  # 0 - 0 >= 0
        (0x942, "red", 6, False),  # the wooden divider: 9 - 4 = 5
        (0x942, "red", 5, True),
        (0xFE8, "yellow", 6, True),  # |15 - 14| <= 2 and 14 - 8 >= 6
        (0xFC8, "yellow", 6, False),  # |15 - 12| = 3 > 2
        (0xF0F, "magenta", 6, True),
        (0x0FF, "cyan", 6, True),
        (0xCCC, "white", 6, True),  # min 12 >= white_min 12
        (0xBBB, "white", 6, False),
        (0xEFD, "white", 6, True),  # max - min = 2
        (0x123, "none", 6, True),
    ],
)
def test_filter_hand_computed_pixels(pixel, colour, diff_min, matches):
    params = FollowTargetParams(width=16, height=2, margin_x=0, margin_y=0, diff_min=diff_min)
    frame = np.full((2, 16), pixel, np.uint16)
    assert color_match(frame, colour, params).all() == matches
    assert color_match(frame, COLOR_SELECT[colour], params).any() == matches


def test_filter_rejects_frames_of_the_wrong_shape_or_dtype():
    params = FollowTargetParams()
    with pytest.raises(FrameError, match=r"shape \(120, 160\)"):
        color_match(np.zeros((120, 161), np.uint16), "red", params)
    with pytest.raises(FrameError, match="unsigned"):
        color_match(np.zeros((120, 160), np.int32), "red", params)


# Tracker ------------------------------------------------------------------------------------


def _loop_leds(bins, n, found):
    """The LED code written out branch by branch, for comparison with the model."""
    if not found:
        return 0
    left, right = bins[0] + bins[1] + bins[2] + bins[3], bins[4] + bins[5] + bins[6] + bins[7]
    half = n // 2
    if abs(left - right) < n // 16:
        return 0x18
    if left > right:
        if bins[0] >= half:
            return 0x01
        if bins[0] + bins[1] >= half:
            return 0x02
        if bins[0] + bins[1] + bins[2] >= half:
            return 0x04
        return 0x08
    if bins[7] >= half:
        return 0x80
    if bins[6] + bins[7] >= half:
        return 0x40
    if bins[5] + bins[6] + bins[7] >= half:
        return 0x20
    return 0x10


@st.composite
def _tracker_case(draw):
    bin_width = draw(st.integers(1, 4))
    margin_x = draw(st.integers(0, 6))
    width = max(16, 8 * bin_width + 2 * margin_x)
    margin_x = (width - 8 * bin_width) // 2
    height = draw(st.integers(2, 14))
    margin_y = draw(st.integers(0, (height - 1) // 2))
    window = 8 * bin_width * (height - 2 * margin_y)
    min_pixels = draw(st.integers(1, window + 1))
    thresholds = sorted(draw(st.lists(st.integers(0, window + 2), min_size=7, max_size=7)))
    params = FollowTargetParams(
        width=width,
        height=height,
        margin_x=margin_x,
        margin_y=margin_y,
        min_pixels=min_pixels,
        proximity_thresholds=tuple(thresholds),
    )
    density = draw(st.sampled_from([0.02, 0.2, 0.5, 0.9, 1.0]))
    seed = draw(st.integers(0, 2**32 - 1))
    match = np.random.default_rng(seed).random((height, width)) < density
    return params, match


@settings(max_examples=150, deadline=None)
@given(_tracker_case())
def test_tracker_agrees_with_a_loop_over_pixels(case):
    params, match = case
    rows = match.tolist()
    n, bins, sum_x = loop_track(rows, params)
    found = n >= params.min_pixels
    result = track_frame(match, params)
    assert result.count == n
    assert list(result.bins) == bins
    assert result.sum_x == sum_x
    assert result.found == found
    assert result.proximity == len([t for t in params.proximity_thresholds if n >= t])
    assert result.centroid_x == (sum_x // n if found else 0)
    assert result.centroid_leds == _loop_leds(bins, n, found)
    assert result.left_count + result.right_count == n


def test_window_edges_and_bin_boundaries_at_160x120():
    params = FollowTargetParams(min_pixels=1)
    match = np.zeros((120, 160), bool)
    match[:8, :] = match[112:, :] = True  # top and bottom margins: not counted
    match[:, :16] = match[:, 144:] = True  # left and right margins: not counted
    assert track_frame(match, params).count == 0
    match[:] = False
    match[8, 16] = True  # first window column: bin 0
    match[111, 31] = True  # last column of bin 0
    match[50, 32] = True  # first column of bin 1
    match[60, 79] = True  # last column of bin 3 (left half)
    match[60, 80] = True  # first column of bin 4 (right half)
    match[9, 143] = True  # last window column: bin 7 (right, not left as in the published RTL)
    r = track_frame(match, params)
    assert r.bins == (2, 1, 0, 1, 1, 0, 0, 1)
    assert (r.left_count, r.right_count) == (4, 2)
    assert r.sum_x == 16 + 31 + 32 + 79 + 80 + 143
    assert r.centroid_x == (16 + 31 + 32 + 79 + 80 + 143) // 6 == 63


def test_centroid_is_floor_of_the_mean_and_zero_when_not_found():
    params = FollowTargetParams(min_pixels=2)
    match = np.zeros((120, 160), bool)
    match[20, 16] = match[21, 17] = True
    r = track_frame(match, params)
    assert (r.found, r.count, r.sum_x, r.centroid_x) == (True, 2, 33, 16)
    match[21, 17] = False
    r = track_frame(match, params)
    assert (r.found, r.count, r.centroid_x, r.centroid_leds) == (False, 1, 0, 0)


def _window_with(count):
    """A 160x120 mask with ``count`` matching pixels filling window rows from the top."""
    match = np.zeros((120, 160), bool)
    window = np.zeros(104 * 128, bool)
    window[:count] = True
    match[8:112, 16:144] = window.reshape(104, 128)
    return match


@pytest.mark.parametrize(
    "count,proximity",
    [
        (0, 0),
        (127, 0),
        (128, 1),
        (255, 1),
        (256, 2),
        (511, 2),
        (512, 3),
        (1024, 4),
        (2048, 5),
        (4095, 5),
        (4096, 6),
        (6143, 6),
        (6144, 7),
        (128 * 104, 7),
    ],
)
def test_default_proximity_levels_including_1_and_2(count, proximity):
    params = FollowTargetParams()
    r = track_frame(_window_with(count), params)
    assert r.count == count
    assert r.proximity == proximity
    assert r.found == (count >= 128)


def test_approaching_target_passes_through_every_proximity_level():
    model = FollowTargetModel()
    levels = [
        model.process(synthetic.as_rgb444(f), "red").tracker.proximity
        for f in synthetic.scenario("approach", rng=4).frames
    ]
    assert levels == sorted(levels)
    assert set(levels) == set(range(1, 8))


@pytest.mark.parametrize(
    "bins,leds",
    [
        ((64, 0, 0, 0, 0, 0, 0, 64), 0x18),  # L == R
        ((34, 0, 0, 33, 0, 0, 0, 61), 0x18),  # |67 - 61| = 6 < 128 >> 4 = 8: centred
        # |68 - 60| = 8 is not < 8, L > R; h0, h0 + h1, h0 + h1 + h2 are all 34 < 64: LED 3.
        ((34, 0, 0, 34, 0, 0, 0, 60), 0x08),
        ((70, 10, 0, 0, 48, 0, 0, 0), 0x01),  # L > R, h0 = 70 >= half 64
        ((30, 40, 10, 0, 48, 0, 0, 0), 0x02),  # h0 + h1 = 70
        ((20, 20, 30, 10, 48, 0, 0, 0), 0x04),  # h0 + h1 + h2 = 70
        ((10, 10, 10, 50, 48, 0, 0, 0), 0x08),  # never reaches 64 before h3
        ((48, 0, 0, 0, 0, 0, 10, 70), 0x80),  # R > L, h7 = 70 >= 64
        ((48, 0, 0, 0, 0, 10, 40, 30), 0x40),  # h6 + h7 = 70
        ((48, 0, 0, 0, 10, 30, 20, 20), 0x20),  # h5 + h6 + h7 = 70
        ((48, 0, 0, 0, 50, 10, 10, 10), 0x10),  # never reaches 64 from the right before h4
    ],
)
def test_centroid_leds_every_branch(bins, leds):
    n = sum(bins)
    assert n == 128
    assert centroid_leds(bins, n, True) == leds
    assert centroid_leds(bins, n, False) == 0


def test_centroid_leds_with_fewer_than_16_pixels_is_never_centred():
    # N >> 4 = 0 and nothing is < 0: L == R falls through to the right-hand branch.
    assert centroid_leds((4, 0, 0, 0, 0, 0, 0, 4), 8, True) == 0x80
    assert centroid_leds((0, 0, 0, 4, 4, 0, 0, 0), 8, True) == 0x10


def test_tracker_leds_from_a_frame():
    params = FollowTargetParams()
    match = np.zeros((120, 160), bool)
    match[20:52, 16:20] = True  # 128 pixels in bin 0
    match[20:36, 140:144] = True  # 64 pixels in bin 7
    r = track_frame(match, params)
    assert r.bins == (128, 0, 0, 0, 0, 0, 0, 64)
    assert r.centroid_leds == 0x01  # half = 96, h0 = 128


# Motor controller ---------------------------------------------------------------------------


def _seen(centroid_x, proximity=1):
    return TrackerResult(True, proximity, centroid_x, 0, 200, (0,) * 8, 0)


NOT_SEEN = TrackerResult(False, 0, 0, 0, 0, (0,) * 8, 0)


def test_motor_outputs_zero_after_reset_and_left_as_last_side():
    m = MotorModel(FollowTargetParams())
    assert (m.left, m.right, m.lost_count, m.last_side) == (0, 0, 0, "left")


@pytest.mark.parametrize(
    "kw,centroid_x,proximity,expected",
    [
        # kp_num 3, e = 0 - 80 = -80: turn = -240; 400 - 240 = 160, 400 + 240 = 640 -> 512.
        ({}, 0, 1, (160, 512)),
        # e = 159 - 80 = 79: turn 237; base 300 (level 2): 537 -> 512, 63.
        ({}, 159, 2, (512, 63)),
        ({}, 80, 7, (-150, -150)),  # centred, backing off
        # kp_shift 2: 3 * -5 = -15, >> 2 = -4 (floor), not -3.
        ({"kp_shift": 2}, 75, 3, (196, 204)),
        ({"kp_shift": 2}, 85, 3, (203, 197)),  # 15 >> 2 = 3
        ({"kp_shift": 3, "kp_num": -7}, 81, 1, (399, 401)),  # -7 >> 3 = -1
        ({"max_dps": 100}, 90, 1, (100, 100)),  # 430 and 370 both saturate
        ({"max_dps": 100}, 80, 6, (-100, -100)),
        ({"max_dps": 0}, 10, 4, (0, 0)),
    ],
)
def test_motor_turn_shift_and_saturation_by_hand(kw, centroid_x, proximity, expected):
    m = MotorModel(FollowTargetParams(**kw))
    assert m.step(_seen(centroid_x, proximity)) == expected
    assert (m.left, m.right) == expected


@settings(max_examples=200, deadline=None)
@given(
    kp_num=st.integers(-(2**15), 2**15 - 1),
    kp_shift=st.integers(0, 15),
    max_dps=st.integers(0, 2**15 - 1),
    proximity=st.integers(0, 7),
    centroid_x=st.integers(0, 159),
)
def test_motor_law_is_floor_division_then_clamp(kp_num, kp_shift, max_dps, proximity, centroid_x):
    params = FollowTargetParams(kp_num=kp_num, kp_shift=kp_shift, max_dps=max_dps)
    e = centroid_x - 80
    turn = (kp_num * e) // (2**kp_shift)  # floor division, written without a shift
    base = params.base_dps[proximity]

    def clamp(v):
        return min(max(v, -max_dps), max_dps)

    m = MotorModel(params)
    assert m.step(_seen(centroid_x, proximity)) == (clamp(base + turn), clamp(base - turn))
    assert m.last_side == ("right" if centroid_x >= 80 else "left")


def test_lost_and_search_sequence_frame_by_frame():
    m = MotorModel(FollowTargetParams(lost_frames=3, search_dps=250))
    steps = [
        # (input, expected (left, right), lost_count, last_side)
        (NOT_SEEN, (0, 0), 1, "left"),  # after reset: hold 0
        (NOT_SEEN, (0, 0), 2, "left"),
        (NOT_SEEN, (-250, 250), 3, "left"),  # count reaches 3: search towards left
        (NOT_SEEN, (-250, 250), 3, "left"),
        (_seen(100), (460, 340), 0, "right"),  # e = 20, turn 60, base 400
        (NOT_SEEN, (460, 340), 1, "right"),  # hold the last command
        (NOT_SEEN, (460, 340), 2, "right"),
        (NOT_SEEN, (250, -250), 3, "right"),  # search towards right
        (_seen(80), (400, 400), 0, "right"),  # e = 0 counts as right
        (NOT_SEEN, (400, 400), 1, "right"),
        (_seen(70), (370, 430), 0, "left"),  # found again resets the count
        (NOT_SEEN, (370, 430), 1, "left"),
        (NOT_SEEN, (370, 430), 2, "left"),
        (NOT_SEEN, (-250, 250), 3, "left"),
        (NOT_SEEN, (-250, 250), 3, "left"),
    ]
    for i, (tracker, outputs, lost, side) in enumerate(steps):
        assert m.step(tracker) == outputs, f"frame {i}"
        assert (m.lost_count, m.last_side) == (lost, side), f"frame {i}"
    m.reset()
    assert (m.left, m.right, m.lost_count, m.last_side) == (0, 0, 0, "left")


def test_lost_frames_1_searches_on_the_first_lost_frame():
    m = MotorModel(FollowTargetParams(lost_frames=1, search_dps=-30))
    assert m.step(_seen(120)) == (512, 400 - 120)  # 400 + 120 saturates
    assert m.step(NOT_SEEN) == (-30, 30)  # right side, with a negative search speed


def test_search_speed_extremes_negate_without_wrapping():
    # search_dps is limited to +-32767 (params), so both wheels' values fit 16 bits.
    m = MotorModel(FollowTargetParams(lost_frames=1, search_dps=-(2**15) + 1))
    assert m.step(NOT_SEEN) == (2**15 - 1, -(2**15) + 1)  # last_side left after reset
    m = MotorModel(FollowTargetParams(lost_frames=1, search_dps=2**15 - 1))
    assert m.step(NOT_SEEN) == (-(2**15) + 1, 2**15 - 1)


def test_default_lost_frames_holds_14_frames_and_searches_on_the_15th():
    m = MotorModel(FollowTargetParams())
    tracking = m.step(_seen(40))  # left of centre
    outputs = [m.step(NOT_SEEN) for _ in range(16)]
    assert outputs[:14] == [tracking] * 14
    assert outputs[14:] == [(-250, 250)] * 2


def test_found_with_proximity_zero_uses_base_dps_0():
    params = FollowTargetParams(min_pixels=10, base_dps=(7, 400, 300, 200, 150, 100, -100, -150))
    model = FollowTargetModel(params)
    frame = np.zeros((120, 160), np.uint16)
    frame[60, 80:90] = 0xF00  # 10 red pixels: found, below the first threshold 128
    out = model.process(frame, "red")
    assert (out.tracker.found, out.tracker.proximity, out.tracker.centroid_x) == (True, 0, 84)
    assert (out.motor_left, out.motor_right) == (7 + 12, 7 - 12)


# Whole model ---------------------------------------------------------------------------------


def test_model_follows_the_lost_scenario_and_resets():
    params = FollowTargetParams(lost_frames=4)
    sc = synthetic.scenario("lost", lost_frames=4, n_frames=2, rng=11)
    model = FollowTargetModel(params)
    outs = [model.process(f, "red") for f in sc.frames]  # RGB888 accepted too
    seen = [o.tracker.found for o in outs]
    assert seen == [s.visible for s in sc.states]
    right = outs[0].tracker.centroid_x
    assert right == 120  # the disc is symmetric about x = 0.75 * 160
    assert outs[0].tracker.proximity == 3
    track = (200 + 3 * 40, 200 - 3 * 40)
    assert [(o.motor_left, o.motor_right) for o in outs] == (
        [track] * 2 + [track] * 3 + [(250, -250)] * 4 + [(200 - 120, 200 + 120)] * 2
    )
    # Disc over columns 106..134: h6 + h7 (columns 112..143) holds more than half.
    assert outs[0].tracker.centroid_leds == 0x40
    model.reset()
    again = model.process(sc.frames[5], "red")  # lost right after reset: hold 0
    assert (again.motor_left, again.motor_right) == (0, 0)


def test_model_filtered_frame_and_colour_choice():
    frame = synthetic.blob_frame(160, 120, "green", radius=10, rng=2)
    packed = synthetic.as_rgb444(frame)
    model = FollowTargetModel()
    red = model.process(packed, "red")
    assert not red.filtered.any() and not red.tracker.found
    green = model.process(packed, "green")
    mask = synthetic.Blob("green", 80, 60, radius=10).mask(160, 120)
    assert np.array_equal(green.filtered != 0, mask)
    assert np.array_equal(green.filtered[mask], packed[mask])
    assert green.tracker.count == mask.sum() and green.tracker.centroid_x == 80
    # Radius 10: 317 pixels; column 80 (21 pixels) is in the right half, so R - L = 21,
    # not < 317 >> 4 = 19: not "centred"; no right-hand bin group reaches half: LED 4.
    assert green.tracker.count == 317
    assert green.tracker.centroid_leds == 0x10


def test_model_rejects_bad_frames():
    model = FollowTargetModel(FollowTargetParams(width=48, height=16))
    with pytest.raises(FrameError, match="shape"):
        model.process(np.zeros((120, 160), np.uint16), "red")
    with pytest.raises(ValueError, match="unknown colour"):
        model.process(np.zeros((16, 48), np.uint16), "purple")


# The published design's knobs (FollowTargetParams.published(), docs/published.md) -------------

PUBLISHED = FollowTargetParams.published()


@pytest.mark.parametrize(
    "count,ge,gt", [(127, False, False), (128, True, False), (129, True, True)]
)
def test_found_rule_by_hand(count, ge, gt):
    assert is_found(count, FollowTargetParams()) is ge
    assert is_found(count, PUBLISHED) is gt


def test_groups_shifted_by_one_column_by_hand():
    # 160x120: one full column (104 pixels) at each of 79 (last of bin 3) and 143 (last of
    # bin 7). Bins: h3 = h7 = 104. Groups: 79 joins group 4, 143 wraps to group 0.
    match = np.zeros((120, 160), bool)
    match[8:112, [79, 143]] = True
    r0 = track_frame(match, FollowTargetParams())
    r1 = track_frame(match, FollowTargetParams(group_column_offset=1))
    assert r0.bins == r1.bins == (0, 0, 0, 104, 0, 0, 0, 104)
    assert r0.centroid_leds == 0x18  # L = R
    assert r1.centroid_leds == 0x18  # L = G0 = 104, R = G4 = 104: still centred
    # Add a column at 80 (bin 4): exact L = 104 < R = 208, shifted L = 104 < R = 208 too,
    # but from the right edge: h7 = 104 >= half (156)? no; groups 6..7 = 0; 5..7 = 0: LED 4.
    match[8:112, 80] = True
    assert centroid_leds((0, 0, 0, 104, 104, 0, 0, 104), 312, True) == 0x10
    assert track_frame(match, FollowTargetParams(group_column_offset=1)).centroid_leds == 0x10
    # The outermost single bins are exact: 104 pixels in column 31 (last of bin 0) still
    # make h0 reach half although column 31 counts in group 1.
    groups = (0, 104, 0, 0, 0, 0, 0, 0)
    assert centroid_leds((104, 0, 0, 0, 0, 0, 0, 0), 104, True, groups) == 0x01


@pytest.mark.parametrize(
    "speed,code,expected",
    [
        (600, 0x01, (325, 600)),
        (600, 0x02, (375, 600)),
        (600, 0x04, (425, 600)),
        (600, 0x08, (475, 600)),
        (600, 0x10, (600, 475)),
        (600, 0x80, (600, 325)),
        (350, 0x18, (350, 350)),
        (150, 0x40, (150, -75)),
        (-250, 0x01, (-250, 25)),
        (-450, 0x80, (-175, -450)),
        (-450, 0x18, (-450, -450)),
        (600, 0x00, (0, 0)),  # never seen
    ],
)
def test_table_command_by_hand(speed, code, expected):
    assert table_command(speed, code, PUBLISHED) == expected


def test_table_law_drives_on_while_lost_and_remembers_the_leds():
    m = MotorModel(PUBLISHED)
    seen = TrackerResult(True, 4, 10, 0x04, 3100, (0,) * 8, 0)
    lost = TrackerResult(False, 0, 0, 0, 0, (0,) * 8, 0)
    lost_128 = TrackerResult(False, 3, 0, 0, 128, (0,) * 8, 0)
    assert m.step(seen) == (250 - 175, 250)
    assert m.step(lost) == (600 - 175, 600) and m.last_leds == 0x04
    assert m.step(lost_128) == (350 - 175, 350)
    for _ in range(12):  # lost frames 3..14
        m.step(lost)
    assert m.lost_count == 14 and (m.left, m.right) == (425, 600)
    assert m.step(lost) == (-250, 250)  # the 15th: search left (the LEDs' side)
    m.reset()
    assert (m.left, m.right, m.last_leds, m.last_side) == (0, 0, 0, "left")


def test_a_narrow_sx_wraps_and_moves_the_centroid_off_centre():
    # Story (d) (docs/stories.md): a person centred on column 80, columns 60..99 over rows
    # 30..79, at 160x120. N = 40 * 50 = 2000; SX = 50 * (60 + ... + 99) = 50 * 3180 = 159000,
    # the centroid 159000 // 2000 = 79. In 17 bits SX wraps at 131072: 159000 - 131072 = 27928,
    # the centroid 27928 // 2000 = 13.
    match = np.zeros((120, 160), bool)
    match[30:80, 60:100] = True
    full = track_frame(match, FollowTargetParams())
    assert (full.count, full.sum_x, full.centroid_x) == (2000, 159000, 79)
    narrow = track_frame(match, FollowTargetParams(sx_bits=17))
    assert (narrow.count, narrow.sum_x, narrow.centroid_x) == (2000, 27928, 13)
    # Only SX and the centroid change: N, the bins, found, proximity and the LEDs do not.
    assert narrow == replace(full, sum_x=27928, centroid_x=13)
    # 18 bits hold 159000 (< 262144): no wrap; 16 bits wrap it twice: 159000 - 2 * 65536 = 27928.
    assert track_frame(match, FollowTargetParams(sx_bits=18)) == full
    assert track_frame(match, FollowTargetParams(sx_bits=16)).sum_x == 27928
    # 12 bits: 159000 = 38 * 4096 + 3352; 3352 // 2000 = 1.
    assert track_frame(match, FollowTargetParams(sx_bits=12)).centroid_x == 1
