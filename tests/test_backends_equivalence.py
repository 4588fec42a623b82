"""Every backend gives the golden model's FrameResults, frame by frame.

Multi-frame sequences (random frames, targets of several colours, an approaching target, a
target lost for longer than ``lost_frames`` so that the motors search, then found again) run
through ``model``, ``pysim``, ``cxxrtl`` and ``verilator`` at two small geometries with
non-default parameters, with and without blanking; the compiled backends also at 160x120.
Equal ``cycles`` means the clocked backends saw ``frame_done`` exactly where the documented
latency puts it. Builds are shared through module-scoped fixtures and the on-disk cache.
"""

import importlib.util

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.sim.backends import BackendError, get_backend
from fpga_robotics.sim.camera import synthetic

# Small geometries with thresholds low enough that their blobs reach every proximity level.
SMALL_A = FollowTargetParams(
    width=40,
    height=16,
    diff_min=5,
    min_pixels=4,
    proximity_thresholds=(4, 8, 16, 32, 64, 96, 128),
    base_dps=(0, 300, 250, 200, 120, 60, -40, -90),
    kp_num=5,
    kp_shift=1,
    max_dps=280,
    lost_frames=3,
    search_dps=-120,
)
SMALL_B = FollowTargetParams(
    width=48,
    height=24,
    similar_max=3,
    white_min=10,
    min_pixels=8,
    proximity_thresholds=(8, 16, 32, 64, 128, 256, 384),
    lost_frames=2,
    search_dps=90,
)
BLANKINGS = [(0, 0), (3, 40)]


def has_pysim():
    return importlib.util.find_spec("fpga_robotics.sim.backends.pysim") is not None


def frame_sequence(params, seed):
    """(frame, colour) pairs: a searching sequence, an approach, colours, random frames."""
    w, h = params.width, params.height
    rng = np.random.default_rng(seed)
    seq = []
    lost = synthetic.scenario("lost", w, h, n_frames=2, lost_frames=params.lost_frames, rng=rng)
    seq += [(f, "red") for f in lost.frames]
    approach = synthetic.scenario("approach", w, h, color="green", n_frames=5, rng=rng)
    seq += [(f, "green") for f in approach.frames]
    for i, colour in enumerate(("blue", "yellow", "magenta", "cyan", "white")):
        cx = w * (0.2 + 0.15 * i)
        frame = synthetic.blob_frame(w, h, colour, cx=cx, radius=h / 4, rng=rng)
        seq.append((frame, colour))
    for code in range(8):  # random pixels match some of every colour, and "none" all
        seq.append((synthetic.random_frame(w, h, rng=rng), code))
    seq.append((synthetic.as_rgb444(synthetic.empty_frame(w, h, rng=rng)), "red"))
    return seq


def run(backend, seq):
    return [backend.process_frame(frame, colour) for frame, colour in seq]


def assert_same(reference, results, name):
    assert len(reference) == len(results)
    for i, (ref, got) in enumerate(zip(reference, results, strict=True)):
        if got.outputs() != ref.outputs():
            fields = (
                "found",
                "proximity",
                "centroid_x",
                "centroid_leds",
                "motor_left",
                "motor_right",
                "cycles",
            )
            diff = {
                f: (r, g)
                for f, r, g in zip(fields, ref.outputs(), got.outputs(), strict=True)
                if r != g
            }
            pytest.fail(f"{name}: frame {i}: (model, {name}) differ in {diff}")
        if not np.array_equal(got.filtered, ref.filtered):
            bad = np.argwhere(got.filtered != ref.filtered)
            y, x = bad[0]
            pytest.fail(
                f"{name}: frame {i}: {len(bad)} filtered pixels differ, first at (y={y}, x={x}): "
                f"model {ref.filtered[y, x]:#05x}, {name} {got.filtered[y, x]:#05x}"
            )
        assert got.filtered.dtype == np.uint16 and got.filtered.shape == ref.filtered.shape


def reference(params, seq, line_blank, frame_blank):
    with get_backend("model", params, line_blank=line_blank, frame_blank=frame_blank) as m:
        return run(m, seq)


def test_sequences_exercise_search_every_proximity_and_colour():
    """The stimulus is worth comparing: the model sees searching motors, several proximity
    levels, every colour code and frames without a target."""
    seq = frame_sequence(SMALL_A, 1)
    ref = reference(SMALL_A, seq, 0, 0)
    search = (SMALL_A.search_dps, -SMALL_A.search_dps)
    assert any((r.motor_left, r.motor_right) in (search, search[::-1]) for r in ref)
    assert len({r.proximity for r in ref}) >= 4
    assert any(not r.found for r in ref) and any(r.found for r in ref)
    assert {COLOR_SELECT.get(c, c) for _, c in seq} == set(range(8))


@pytest.mark.parametrize("params", [SMALL_A, SMALL_B], ids=["40x16", "48x24"])
@pytest.mark.parametrize("blanking", BLANKINGS, ids=["no-blank", "blank"])
@pytest.mark.parametrize(
    "name", ["pysim", "cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)]
)
def test_backend_matches_model_frame_by_frame(name, params, blanking):
    if name == "pysim" and not has_pysim():
        pytest.skip("the pysim backend (gateware helper) is not in this tree yet")
    seq = frame_sequence(params, 7)
    line_blank, frame_blank = blanking
    ref = reference(params, seq, line_blank, frame_blank)
    with get_backend(name, params, line_blank=line_blank, frame_blank=frame_blank) as b:
        assert_same(ref, run(b, seq), name)
        # reset() returns to the power-on state: the sequence gives the same results again.
        b.reset()
        assert_same(ref[:6], run(b, seq[:6]), f"{name} after reset")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["cxxrtl", "verilator"])
def test_compiled_backend_matches_model_at_160x120(name):
    params = FollowTargetParams()
    rng = np.random.default_rng(3)
    seq = [(f, "red") for f in synthetic.scenario("lost", rng=rng).frames]
    seq += [(f, "red") for f in synthetic.scenario("approach", n_frames=8, rng=rng).frames]
    seq += [(synthetic.random_frame(160, 120, rng=rng), c) for c in ("white", "cyan")]
    for line_blank, frame_blank in BLANKINGS:
        ref = reference(params, seq, line_blank, frame_blank)
        with get_backend(name, params, line_blank=line_blank, frame_blank=frame_blank) as b:
            assert_same(ref, run(b, seq), name)


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_wrong_frames_give_clear_errors_and_change_nothing(name):
    from fpga_robotics.sim.camera.frames import FrameError

    p = SMALL_A
    seq = frame_sequence(p, 2)[:3]
    ref = reference(p, seq, 0, 0)
    with get_backend(name, p) as b:
        with pytest.raises(FrameError, match=r"shape \(16, 40, 3\)"):
            b.process_frame(np.zeros((16, 41, 3), np.uint8))
        with pytest.raises(FrameError, match="must be uint8"):
            b.process_frame(np.zeros((16, 40, 3), np.float32))
        with pytest.raises(FrameError, match="unsigned integer"):
            b.process_frame(np.zeros((16, 40), np.int32))
        with pytest.raises(ValueError, match="unknown colour"):
            b.process_frame(seq[0][0], "purple")
        assert b.frames_processed == 0
        assert_same(ref, run(b, seq), name)


def test_watchdog_turns_a_missing_frame_done_into_backend_error():
    """The harness stops a frame whose frame_done never comes (here: the driver is told the
    frame has one line fewer than the design counts, so the design never ends it)."""
    with get_backend("cxxrtl", SMALL_A) as b:
        b._args[1] = SMALL_A.height - 1
        with pytest.raises(BackendError, match="never raised frame_done"):
            b.process_frame(np.zeros((16, 40), np.uint16))


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_both_harness_loops_agree_with_hand_computed_pass_through(name):
    """The one-evaluation loop (outputs are flip-flops) and the general two-evaluation loop
    (combinational outputs) give the same, hand-computable results for the pass-through
    design: filtered = the frame, motor_left = the pixel count, cycles = pixels + blanking
    (its result latency is 1, motor latency 0)."""
    from fpga_robotics.sim.backends.cxxrtl_netlist import output_sources
    from fpga_robotics.sim.backends.designs import DesignSource

    p = FollowTargetParams(width=40, height=16)
    assert output_sources(DesignSource(p, "passthrough").cxxrtl()) is not None
    assert output_sources(DesignSource(p, "passthrough_comb").cxxrtl()) is None
    rng = np.random.default_rng(11)
    frames = [rng.integers(0, 4096, (16, 40), dtype=np.uint16) for _ in range(3)]
    for line_blank, frame_blank in BLANKINGS:
        expected_cycles = max(
            16 * (40 + line_blank) + frame_blank, 16 * (40 + line_blank) - line_blank + 1
        )
        for design in ("passthrough", "passthrough_comb"):
            with get_backend(
                name, p, design=design, line_blank=line_blank, frame_blank=frame_blank
            ) as b:
                for frame in frames:
                    r = b.process_frame(frame)
                    assert np.array_equal(r.filtered, frame), design
                    assert (r.found, r.motor_left, r.centroid_leds) == (True, 640, 640 & 0xFF)
                    assert r.cycles == expected_cycles, design
