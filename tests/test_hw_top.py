"""FollowTarget (filter + tracker + motor) against the golden ``FollowTargetModel`` over frame
sequences, with blanking, documented latencies, malformed framing and a full-size frame."""

import numpy as np
import pytest
from amaranth.hdl import Fragment
from hwsim import (
    TOP_OUTPUTS,
    Step,
    edges_where,
    frame_schedule,
    lines_schedule,
    run_follow_target,
    small_params,
)

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.hw.top import FollowTarget
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.models.follow_target import FollowTargetModel

COLOURS = [c for c in COLOR_SELECT if c != "none"]


def packed(rgb, p):
    return to_rgb444(rgb, p.width, p.height)


def model_run(p, frames, sels):
    model = FollowTargetModel(p)
    return [model.process(f, s) for f, s in zip(frames, sels)]


def frame_outputs(trace, j):
    """The per-frame outputs at trace index j (motors: motor_latency later)."""
    return {name: int(trace[name][j]) for name in TOP_OUTPUTS}


def check_against_model(p, frames, sels, trace, last_index):
    expected = model_run(p, frames, sels)
    valid = trace["filtered_valid"].astype(bool)
    got_filtered = trace["filtered_payload"][valid] & 0xFFF
    assert np.array_equal(got_filtered, np.concatenate([e.filtered.ravel() for e in expected]))
    done = edges_where(trace, "frame_done")
    assert done == [k + p.result_latency for k in last_index]
    for j, e in zip(done, expected):
        t = e.tracker
        shown = frame_outputs(trace, j)
        assert (
            shown["found"],
            shown["proximity"],
            shown["centroid_x"],
            shown["centroid_leds"],
        ) == (t.found, t.proximity, t.centroid_x, t.centroid_leds)
        motors = frame_outputs(trace, j + p.motor_latency)
        assert (motors["motor_left"], motors["motor_right"]) == (e.motor_left, e.motor_right)
    return expected


def scene_frames(p, seed):
    """Targets of every colour at the edges and the centre, distractors, then empty frames
    (enough to enter search mode), random frames."""
    rng = np.random.default_rng(seed)
    frames, sels = [], []
    positions = [p.margin_x, p.width / 2, p.width - p.margin_x - 1, p.width / 4]
    for i, colour in enumerate(COLOURS):
        cx = positions[i % len(positions)]
        rgb = synthetic.blob_frame(
            p.width, p.height, colour, cx=cx, cy=p.height / 2, radius=p.height / 3, rng=rng
        )
        frames.append(packed(rgb, p))
        sels.append(COLOR_SELECT[colour])
    for _ in range(p.lost_frames + 1):
        frames.append(packed(synthetic.empty_frame(p.width, p.height, rng=rng), p))
        sels.append(COLOR_SELECT["red"])
    frames.append(packed(synthetic.random_frame(p.width, p.height, rng=rng), p))
    sels.append(COLOR_SELECT["none"])
    frames.append(packed(synthetic.random_frame(p.width, p.height, rng=rng), p))
    sels.append(COLOR_SELECT["yellow"])
    return frames, sels


def test_scenes_of_every_colour_with_blanking_match_the_model():
    p = small_params()
    frames, sels = scene_frames(p, seed=1)
    rng = np.random.default_rng(2)
    gaps = {
        int(i): int(n)
        for i, n in zip(rng.integers(1, p.pixels_per_frame, 30), rng.integers(1, 4, 30))
    }
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels, line_blank=2, frame_gap=5, gaps=gaps)
    expected = check_against_model(p, frames, sels, trace, last)
    # The sequence exercises tracking, holding and search in both directions.
    motors = {(e.motor_left, e.motor_right) for e in expected}
    assert (-p.search_dps, p.search_dps) in motors or (p.search_dps, -p.search_dps) in motors
    assert any(e.tracker.found for e in expected) and not all(e.tracker.found for e in expected)


def test_back_to_back_frames_without_any_blanking():
    p = small_params(lost_frames=2)
    frames, sels = scene_frames(p, seed=3)
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels)
    check_against_model(p, frames, sels, trace, last)


def test_documented_latencies_and_strobe():
    p = small_params()
    rng = np.random.default_rng(4)
    frames = [
        packed(synthetic.blob_frame(p.width, p.height, "green", cx=x, radius=4, rng=rng), p)
        for x in (10, 40)
    ]
    sels = [COLOR_SELECT["green"]] * 2
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels, line_blank=1, frame_gap=30)
    assert all(e.tracker.found for e in check_against_model(p, frames, sels, trace, last))
    # filter_latency: first input pixel at schedule index 0 is sampled on `filtered` at edge
    # 1 + filter_latency, i.e. valid at trace index filter_latency - 1.
    assert edges_where(trace, "filtered_valid")[0] == p.filter_latency - 1
    done = edges_where(trace, "frame_done")
    assert done == [k + p.result_latency for k in last]  # result_latency
    for j in done:
        assert trace["frame_done"][j - 1] == 0 and trace["frame_done"][j + 1] == 0
        for name in ("motor_left", "motor_right"):  # motor_latency = 1: still the old value
            assert trace[name][j + p.motor_latency] != trace[name][j]
    # Results hold from one frame_done to the next; motors are 0 until the first one.
    for name in ("found", "proximity", "centroid_x", "centroid_leds"):
        v = trace[name]
        assert np.all(v[: done[0]] == 0) and np.all(v[done[0] : done[1]] == v[done[0]])
    for name in ("motor_left", "motor_right"):
        v = trace[name]
        assert np.all(v[: done[0] + p.motor_latency] == 0)
    assert p.filter_latency <= p.result_latency + p.motor_latency


def test_malformed_frames_between_good_ones_do_not_leak():
    # A frame with a short line and a frame cut short by a new `first` produce no frame_done;
    # the motor state moves only on well-formed frames, as if the others never came.
    p = small_params()
    rng = np.random.default_rng(5)
    good = [
        packed(synthetic.blob_frame(p.width, p.height, "red", cx=x, radius=4, rng=rng), p)
        for x in (12, 30, 36)
    ]
    sel = COLOR_SELECT["red"]
    dut = FollowTarget(p)
    rows = list(good[1])
    short = lines_schedule(rows[:4] + [rows[4][:-3]] + rows[5:])
    cut = frame_schedule(good[2])[: p.width * 5 + 7]
    schedule = []
    last = []
    for part, is_good in (
        (frame_schedule(good[0]), True),
        (short, False),
        (cut, False),
        (frame_schedule(good[1]), True),
        (frame_schedule(good[2]), True),
    ):
        schedule += part
        if is_good:
            last.append(len(schedule) - 1)
        schedule += [None] * 3
    schedule[0] = Step(schedule[0], [(dut.color_sel, sel)])
    trace, _ = run_follow_target(dut, [], [], extra_schedule=schedule)
    expected = model_run(p, good, [sel] * 3)
    done = edges_where(trace, "frame_done")
    assert done == [k + p.result_latency for k in last]
    for j, e in zip(done, expected):
        assert frame_outputs(trace, j)["centroid_x"] == e.tracker.centroid_x
        m = frame_outputs(trace, j + p.motor_latency)
        assert (m["motor_left"], m["motor_right"]) == (e.motor_left, e.motor_right)


def test_full_size_frame_matches_the_model():
    p = FollowTargetParams()
    rng = np.random.default_rng(6)
    frames = [
        packed(synthetic.blob_frame(160, 120, "red", cx=120, cy=50, radius=25, rng=rng), p),
    ]
    sels = [COLOR_SELECT["red"]]
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels)
    expected = check_against_model(p, frames, sels, trace, last)
    assert expected[0].tracker.found and expected[0].tracker.centroid_x > 80


@pytest.mark.parametrize("size", [(320, 240), (640, 480)])
def test_signature_widths_follow_the_geometry(size):
    p = FollowTargetParams(width=size[0], height=size[1])
    dut = FollowTarget(p)
    assert len(dut.centroid_x) == p.x_bits == (size[0] - 1).bit_length()
    assert len(dut.pixels.payload.as_value()) == 14
    assert dut.motor_left.shape().signed and len(dut.motor_left) == 16
    Fragment.get(dut, platform=None)  # and it elaborates at that size


def random_params(rng):
    """A random but valid parameter set at a small geometry."""
    width = int(rng.choice([16, 24, 32, 40, 56]))
    margins = [m for m in range(width // 2) if (width - 2 * m) % 8 == 0 and width > 2 * m]
    height = int(rng.integers(2, 9))
    thresholds = tuple(sorted(int(t) for t in rng.integers(0, width * height, 7)))
    return FollowTargetParams(
        width=width,
        height=height,
        margin_x=int(rng.choice(margins)),
        margin_y=int(rng.integers(0, (height - 1) // 2 + 1)),
        diff_min=int(rng.integers(0, 16)),
        similar_max=int(rng.integers(0, 16)),
        white_min=int(rng.integers(0, 16)),
        min_pixels=int(rng.integers(1, width * height)),
        proximity_thresholds=thresholds,
        base_dps=tuple(int(v) for v in rng.integers(-600, 600, 8)),
        kp_num=int(rng.integers(-60, 61)),
        kp_shift=int(rng.integers(0, 5)),
        max_dps=int(rng.integers(0, 700)),
        lost_frames=int(rng.integers(1, 4)),
        search_dps=int(rng.integers(-300, 301)),
    )


@pytest.mark.parametrize("seed", range(6))
def test_random_parameter_sets_match_the_model(seed):
    rng = np.random.default_rng(100 + seed)
    p = random_params(rng)
    frames, sels = [], []
    for i in range(6):
        if i in (2, 3):  # no target: lost frames
            rgb = synthetic.empty_frame(p.width, p.height, rng=rng)
        else:
            rgb = synthetic.random_frame(p.width, p.height, rng=rng)
        frames.append(packed(rgb, p))
        sels.append(int(rng.integers(0, 8)))
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels, line_blank=int(rng.integers(0, 3)))
    check_against_model(p, frames, sels, trace, last)


def published_small(**changes):
    """The published preset at the small test geometry (counts scaled down by hand)."""
    return FollowTargetParams.published(
        **{
            "width": 48,
            "height": 12,
            "margin_x": 4,
            "margin_y": 1,
            "min_pixels": 8,
            "proximity_thresholds": (8, 8, 8, 30, 60, 100, 200),
            "lost_frames": 3,
            **changes,
        }
    )


def test_published_preset_scenes_match_the_model():
    # The LED code reaches the motor controller (table law, lost motion, search side).
    p = published_small()
    frames, sels = scene_frames(p, 21)
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels, line_blank=1)
    expected = check_against_model(p, frames, sels, trace, last)
    assert {e.tracker.centroid_leds for e in expected} >= {0, 0x18}
    assert len({(e.motor_left, e.motor_right) for e in expected}) >= 5


@pytest.mark.parametrize(
    "seed,law,motion",
    [(0, "table", "drive"), (1, "table", "hold"), (2, "p_control", "hold"), (3, "table", "drive")],
)
def test_random_published_knobs_match_the_model(seed, law, motion):
    rng = np.random.default_rng(300 + seed)
    base = random_params(rng)
    p = base.replace(
        found_rule=str(rng.choice(["ge", "gt"])),
        group_column_offset=int(rng.integers(0, 2)),
        motor_law=law,
        steer_dps=tuple(int(v) for v in rng.integers(0, 400, 4)),
        lost_motion=motion,
        search_side_from=str(rng.choice(["centroid", "leds"])),
        centred_search_side=str(rng.choice(["right", "left"])),
    )
    frames, sels = [], []
    for i in range(7):
        if i in (2, 3, 4):
            rgb = synthetic.empty_frame(p.width, p.height, rng=rng)
        else:
            rgb = synthetic.blob_frame(
                p.width,
                p.height,
                "red",
                cx=rng.random() * p.width,
                cy=p.height / 2,
                radius=p.height / 2,
                rng=rng,
            )
        frames.append(packed(rgb, p))
        sels.append(COLOR_SELECT["red"] if i != 6 else int(rng.integers(0, 8)))
    dut = FollowTarget(p)
    trace, last = run_follow_target(dut, frames, sels, line_blank=int(rng.integers(0, 3)))
    check_against_model(p, frames, sels, trace, last)
