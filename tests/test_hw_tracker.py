"""FrameTracker against the golden model's ``track_frame``: counts, bins, centroid, LEDs,
proximity, latency, back-to-back frames and malformed framing."""

import numpy as np
import pytest
from hwsim import (
    edges_where,
    match_lines_schedule,
    match_transfer,
    run_schedule,
    small_params,
    unpack_lanes,
)

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.tracker import FrameTracker
from fpga_robotics.sim.models.follow_target import TrackerResult, track_frame

RESULTS = ("found", "proximity", "centroid_x", "centroid_leds")


def run_tracker(params, schedule, tail=None):
    """Run a match-stream schedule; return the traces and a list of ``(trace index,
    TrackerResult)`` for every ``frame_done``."""
    dut = FrameTracker(params)
    probes = {name: getattr(dut, name) for name in ("frame_done", *RESULTS, "count", "sum_x")}
    probes["bins"] = dut.bins
    assert dut.latency == tracker_latency(params)
    tail = dut.latency + 8 if tail is None else tail
    trace = run_schedule(dut, dut.matches, schedule, probes, tail=tail)
    results = []
    for j in edges_where(trace, "frame_done"):
        results.append(
            (
                j,
                TrackerResult(
                    found=bool(trace["found"][j]),
                    proximity=int(trace["proximity"][j]),
                    centroid_x=int(trace["centroid_x"][j]),
                    centroid_leds=int(trace["centroid_leds"][j]),
                    count=int(trace["count"][j]),
                    bins=unpack_lanes(trace["bins"][j], params.count_bits, 8),
                    sum_x=int(trace["sum_x"][j]),
                ),
            )
        )
    return trace, results


def frames_schedule(masks):
    """Well-formed frames back to back."""
    return [e for m in masks for e in match_lines_schedule(m)]


def tracker_latency(params):
    """From the match stream (one filter stage after the pixels) to frame_done."""
    return params.result_latency - params.filter_latency


def random_mask(params, rng, density):
    return rng.random((params.height, params.width)) < density


def last_pixel_index(schedule):
    return max(i for i, e in enumerate(schedule) if e is not None)


def test_documented_latency_formula():
    # run_tracker also checks FrameTracker.latency against the params on every run.
    for w, h in ((160, 120), (320, 240), (640, 480), (48, 12)):
        p = FollowTargetParams(width=w, height=h)
        assert p.result_latency == p.x_bits + 4
        assert (p.filter_latency, p.motor_latency) == (1, 1)
    assert FollowTargetParams().result_latency == 12


@pytest.mark.parametrize("density", [0.0, 0.02, 0.1, 0.5, 1.0])
def test_random_masks_match_the_model(density):
    p = small_params()
    rng = np.random.default_rng(int(density * 100))
    masks = [random_mask(p, rng, density) for _ in range(3)]
    schedule = []
    for mask in masks:
        schedule += match_lines_schedule(mask)
    _, results = run_tracker(p, schedule)
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


def test_latency_one_cycle_strobe_and_hold():
    p = small_params()
    rng = np.random.default_rng(1)
    masks = [random_mask(p, rng, 0.3), random_mask(p, rng, 0.05)]
    first = match_lines_schedule(masks[0], line_blank=2)
    gap = [None] * 40
    second = match_lines_schedule(masks[1])
    schedule = first + gap + second
    trace, results = run_tracker(p, schedule)
    ends = [last_pixel_index(first), len(first) + len(gap) + last_pixel_index(second)]
    # frame_done shows right after edge P + latency: trace index (P - 1) + latency.
    assert [j for j, _ in results] == [e + tracker_latency(p) for e in ends]
    done = trace["frame_done"]
    assert done.sum() == 2  # exactly one cycle per frame
    for name in RESULTS:
        v = trace[name]
        j0, j1 = results[0][0], results[1][0]
        # New values appear exactly with frame_done and hold until the next frame_done.
        assert np.all(v[j0:j1] == v[j0])
        assert np.all(v[j1:] == v[j1])
        assert np.all(v[:j0] == 0)  # reset values until the first frame
    assert results[0][1] == track_frame(masks[0], p)
    assert results[1][1] == track_frame(masks[1], p)


def test_back_to_back_frames_without_gaps():
    # The next frame's first pixel follows the last one directly, while the divider of the
    # previous frame is still running: its result must not be disturbed.
    p = small_params()
    rng = np.random.default_rng(7)
    masks = [random_mask(p, rng, d) for d in (0.1, 1.0, 0.0, 0.2, 0.6)]
    schedule = frames_schedule(masks)
    _, results = run_tracker(p, schedule)
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


def test_blanking_inside_lines_and_between_frames():
    p = small_params()
    rng = np.random.default_rng(3)
    masks = [random_mask(p, rng, 0.2) for _ in range(2)]
    gaps = {
        int(i): int(n)
        for i, n in zip(rng.integers(0, p.pixels_per_frame, 40), rng.integers(1, 5, 40))
    }
    schedule = (
        match_lines_schedule(masks[0], line_blank=3, gaps=gaps)
        + [None] * 11
        + match_lines_schedule(masks[1], line_blank=1, gaps=gaps)
    )
    _, results = run_tracker(p, schedule)
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


def window_columns_mask(p, columns, rows=None):
    mask = np.zeros((p.height, p.width), bool)
    rows = range(p.margin_y, p.height - p.margin_y) if rows is None else rows
    for y in rows:
        mask[y, list(columns)] = True
    return mask


def test_bin_boundaries_are_exact():
    # The published design counted the window's rightmost column as left (bins shifted by
    # one column). Each column alone must land in its own bin; margins never count.
    p = small_params()
    masks, expected_bins = [], []
    for x in range(p.width):
        masks.append(window_columns_mask(p, [x]))
        b = [0] * 8
        if p.margin_x <= x < p.width - p.margin_x:
            b[(x - p.margin_x) // p.bin_width] = p.window_height
        expected_bins.append(tuple(b))
    schedule = frames_schedule(masks)
    _, results = run_tracker(p, schedule)
    assert [r.bins for _, r in results] == expected_bins
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]
    rightmost = results[p.width - p.margin_x - 1][1]
    assert rightmost.bins[7] == p.window_height and sum(rightmost.bins[:4]) == 0


def test_rows_outside_the_window_never_count():
    p = small_params()
    mask = np.zeros((p.height, p.width), bool)
    mask[: p.margin_y, :] = True
    mask[p.height - p.margin_y :, :] = True
    _, results = run_tracker(p, match_lines_schedule(mask))
    assert results[0][1].count == 0 and not results[0][1].found


def test_every_proximity_level_occurs():
    # The published design could never show levels 1 and 2.
    p = small_params()
    thresholds = p.proximity_thresholds
    rng = np.random.default_rng(11)
    window = [
        (y, x)
        for y in range(p.margin_y, p.height - p.margin_y)
        for x in range(p.margin_x, p.width - p.margin_x)
    ]
    masks = []
    for n in (0, thresholds[0] - 1, *thresholds, thresholds[1] + 3):
        mask = np.zeros((p.height, p.width), bool)
        for i in rng.permutation(len(window))[:n]:
            mask[window[i]] = True
        masks.append(mask)
    schedule = frames_schedule(masks)
    _, results = run_tracker(p, schedule)
    levels = [r.proximity for _, r in results]
    assert levels == [0, 0, 1, 2, 3, 4, 5, 6, 7, 2]
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


@pytest.mark.parametrize(
    "columns,leds",
    [
        ([4], 0b0000_0001),  # far left: h0 holds half
        ([9, 10], 0b0000_0010),  # bin 1
        ([14], 0b0000_0100),  # bin 2
        ([19], 0b0000_1000),  # bin 3, left of centre
        ([23, 24], 0b0001_1000),  # centred
        ([24], 0b0001_0000),  # bin 4
        ([29], 0b0010_0000),
        ([34], 0b0100_0000),
        ([43], 0b1000_0000),  # rightmost window column
    ],
)
def test_led_codes(columns, leds):
    p = small_params()
    mask = window_columns_mask(p, columns)
    _, results = run_tracker(p, match_lines_schedule(mask))
    assert results[0][1].centroid_leds == leds
    assert results[0][1] == track_frame(mask, p)


def test_centroid_uses_the_full_column_range():
    # A centroid bit range too narrow for the frame was a published bug: check the extremes
    # at a width whose columns need every bit of centroid_x.
    p = small_params(width=64, height=4, margin_x=0, margin_y=0, min_pixels=1)
    assert p.x_bits == 6
    masks = [window_columns_mask(p, [x]) for x in (0, 31, 32, 62, 63)]
    schedule = frames_schedule(masks)
    _, results = run_tracker(p, schedule)
    assert [r.centroid_x for _, r in results] == [0, 31, 32, 62, 63]
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


def test_threshold_above_every_count_never_triggers():
    p = small_params(min_pixels=5000, proximity_thresholds=(0, 1, 2, 3, 4, 5, 1 << 32 - 1))
    mask = np.ones((p.height, p.width), bool)
    _, results = run_tracker(p, match_lines_schedule(mask))
    r = results[0][1]
    assert (r.found, r.proximity, r.centroid_x, r.centroid_leds) == (False, 6, 0, 0)
    assert r == track_frame(mask, p)


def test_full_size_frame_matches_the_model():
    p = FollowTargetParams()
    rng = np.random.default_rng(5)
    mask = np.zeros((p.height, p.width), bool)
    mask[30:90, 100:150] = rng.random((60, 50)) < 0.8
    _, results = run_tracker(p, match_lines_schedule(mask))
    assert results[0][1] == track_frame(mask, p)
    assert results[0][1].found


# --- malformed framing ---------------------------------------------------------------------


def good_and_expected(p, seed=0):
    mask = random_mask(p, np.random.default_rng(seed), 0.3)
    return match_lines_schedule(mask), track_frame(mask, p)


def lines(p, n_lines, length, value=True):
    return [[value] * length for _ in range(n_lines)]


@pytest.mark.parametrize(
    "case",
    [
        "first_in_mid_frame",
        "short_line",
        "long_line",
        "too_few_lines",
        "no_first",
        "stray_last_then_first",
    ],
)
def test_malformed_frame_gives_nothing_and_does_not_leak(case):
    p = small_params()
    W, H = p.width, p.height
    if case == "first_in_mid_frame":
        bad = match_lines_schedule(lines(p, H // 2, W))  # half a frame, then a new `first`
    elif case == "short_line":
        bad = match_lines_schedule(lines(p, 3, W) + lines(p, 1, W - 5) + lines(p, H - 4, W))
    elif case == "long_line":
        bad = match_lines_schedule(lines(p, 3, W) + lines(p, 1, W + 5) + lines(p, H - 4, W))
    elif case == "too_few_lines":
        bad = match_lines_schedule(lines(p, H - 1, W))
    elif case == "no_first":
        bad = match_lines_schedule(lines(p, H, W), first=False)
    else:  # a lone pixel with `last` before any frame, then garbage without `first`
        bad = [match_transfer(1, last=True)] + match_lines_schedule(lines(p, 2, 7), first=False)
    good, expected = good_and_expected(p)
    _, results = run_tracker(p, bad + [None] * 5 + good)
    # Only the well-formed frame produces a frame_done, with its own counts only.
    assert len(results) == 1
    assert results[0][1] == expected
    assert results[0][0] == len(bad) + 5 + last_pixel_index(good) + tracker_latency(p)


def test_too_many_lines_end_the_frame_at_its_last_line():
    # The frame ends at the `last` of line height-1; extra lines are ignored until the next
    # `first`.
    p = small_params()
    rng = np.random.default_rng(4)
    mask = random_mask(p, rng, 0.4)
    extra = rng.random((5, p.width)) < 0.9
    schedule = match_lines_schedule(list(mask) + list(extra))
    good, expected = good_and_expected(p, seed=9)
    _, results = run_tracker(p, schedule + good)
    assert [r for _, r in results] == [track_frame(mask, p), expected]


def test_first_restarts_the_frame_at_any_point():
    p = small_params()
    garbage = match_lines_schedule(lines(p, 5, p.width))[: 5 * p.width - 13]
    good, expected = good_and_expected(p, seed=2)
    for cut in (1, 17, len(garbage)):
        _, results = run_tracker(p, garbage[:cut] + good)
        assert [r for _, r in results] == [expected]


# --- The published design's tracker knobs ----------------------------------------------------


def window_count_mask(p, n, rng):
    """``n`` matching pixels at random places of the window."""
    window = [
        (y, x)
        for y in range(p.margin_y, p.height - p.margin_y)
        for x in range(p.margin_x, p.width - p.margin_x)
    ]
    mask = np.zeros((p.height, p.width), bool)
    for i in rng.permutation(len(window))[:n]:
        mask[window[i]] = True
    return mask


@pytest.mark.parametrize("rule,found", [("ge", [False, True, True]), ("gt", [False, False, True])])
def test_found_rule(rule, found):
    p = small_params(found_rule=rule)
    rng = np.random.default_rng(2)
    masks = [
        window_count_mask(p, n, rng) for n in (p.min_pixels - 1, p.min_pixels, p.min_pixels + 1)
    ]
    _, results = run_tracker(p, frames_schedule(masks))
    assert [r.found for _, r in results] == found
    # Not found: no LED and no centroid; the proximity is counted all the same.
    assert [r.centroid_leds != 0 for _, r in results] == found
    assert [r.proximity for _, r in results] == [0, 1, 1]
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


def test_repeated_proximity_thresholds_skip_levels():
    # The published thresholds: levels 1 and 2 never occur, 128 pixels is level 3.
    p = small_params(proximity_thresholds=(8, 8, 8, 30, 60, 100, 200))
    rng = np.random.default_rng(3)
    counts = (7, 8, 29, 30, 59, 60, 99, 100, 199, 200)
    masks = [window_count_mask(p, n, rng) for n in counts]
    _, results = run_tracker(p, frames_schedule(masks))
    assert [r.proximity for _, r in results] == [0, 3, 3, 4, 4, 5, 5, 6, 6, 7]
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


def boundary_bars(p):
    """Two-column bars on every bin boundary: (last of bin k, first of bin k+1) and (the two
    last columns of bin k), full window height; the window's last column wraps."""
    lasts = [p.margin_x + (k + 1) * p.bin_width - 1 for k in range(8)]
    return [(c, c + 1) for c in lasts[:7]] + [(c - 1, c) for c in lasts]


def test_group_column_offset_moves_each_bins_last_column_to_the_next_group():
    # With bins 5 columns wide: bar (8, 9) is bins 0/1 at offset 0, both group 1 at offset 1.
    offsets = {}
    for offset in (0, 1):
        p = small_params(group_column_offset=offset)
        masks = [window_columns_mask(p, bar) for bar in boundary_bars(p)]
        _, results = run_tracker(p, frames_schedule(masks))
        assert [r for _, r in results] == [track_frame(m, p) for m in masks]
        offsets[offset] = [r.centroid_leds for _, r in results]
    # The same bars as the 160x120 hand-derived table (tests/test_published_frames.py):
    # A_k = (last of bin k, next) for k = 0..6, B_k = (two last of bin k) for k = 0..7.
    a0, b0 = offsets[0][:7], offsets[0][7:]
    a1, b1 = offsets[1][:7], offsets[1][7:]
    assert a0 == [0x01, 0x02, 0x04, 0x18, 0x20, 0x40, 0x80]
    assert b0 == [0x01, 0x02, 0x04, 0x08, 0x10, 0x20, 0x40, 0x80]
    assert a1 == [0x01, 0x04, 0x08, 0x10, 0x20, 0x40, 0x80]
    assert b1 == [0x01, 0x02, 0x04, 0x18, 0x20, 0x40, 0x40, 0x18]


@pytest.mark.parametrize(
    "changes",
    [
        {"group_column_offset": 1},
        {"group_column_offset": 1, "found_rule": "gt"},
        {"group_column_offset": 1, "margin_x": 0, "margin_y": 0},  # the last column is the frame's
        {"group_column_offset": 1, "margin_x": 8, "width": 32, "height": 6, "margin_y": 2},
    ],
)
def test_group_column_offset_random_masks_match_the_model(changes):
    p = small_params(**changes)
    rng = np.random.default_rng(len(changes))
    masks = [random_mask(p, rng, d) for d in (0.05, 0.3, 0.7, 1.0)]
    # Bars on bin edges and the window's right edge, in the window's last rows (found).
    last_rows = range(p.height - p.margin_y - 5, p.height - p.margin_y)
    for bar in (*boundary_bars(p)[5:7], *boundary_bars(p)[-2:]):
        masks.append(window_columns_mask(p, bar, rows=last_rows))
    schedule = frames_schedule(masks)
    _, results = run_tracker(p, schedule)
    assert [r for _, r in results] == [track_frame(m, p) for m in masks]


@pytest.mark.parametrize("sx_bits", [3, 9, 12])
def test_a_narrow_sx_wraps_as_in_the_model(sx_bits):
    # small_params: SX needs 15 bits at most (400 window pixels, columns up to 47). A narrower
    # register wraps SX modulo 2**sx_bits, the centroid is the wrapped SX // N, as in the model
    # (3 bits: narrower than the divider's quotient).
    p = small_params(sx_bits=sx_bits)
    assert p.full_sum_x_bits == 15 and p.sum_x_bits == sx_bits
    rng = np.random.default_rng(sx_bits)
    masks = [random_mask(p, rng, d) for d in (0.05, 0.3, 1.0)]
    masks.append(window_columns_mask(p, range(30, 36)))  # a blob right of the centre
    _, results = run_tracker(p, frames_schedule(masks))
    full = small_params()
    expected = [track_frame(m, p) for m in masks]
    assert [r for _, r in results] == expected
    for m, r in zip(masks, expected, strict=True):
        assert r.sum_x == track_frame(m, full).sum_x % (1 << sx_bits)
    # The stimulus makes SX wrap, and the centroid move, in some frames.
    assert any(
        r.centroid_x != track_frame(m, full).centroid_x
        for m, r in zip(masks, expected, strict=True)
    )
