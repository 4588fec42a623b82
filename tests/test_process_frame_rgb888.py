"""process_frame with an RGB888 frame: packed in the compiled frame loop, bit for bit the
model's; ``out=`` receives the filtered frame without a new array; a wrong ``out=`` is a clear
error that changes nothing."""

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import get_backend
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import FrameError, to_rgb444

P = FollowTargetParams(
    width=40, height=16, diff_min=5, min_pixels=4, proximity_thresholds=(4, 8, 16, 32, 64, 96, 128)
)
COMPILED = ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)]


def frames(seed, count=12):
    """Random RGB888 frames (every byte, so the low nibbles that packing drops vary too) and
    frames with a target of each colour, with the colour select each is run with."""
    rng = np.random.default_rng(seed)
    seq = []
    for i in range(count):
        seq.append(
            (rng.integers(0, 256, (P.height, P.width, 3), dtype=np.uint8), ("red", "green")[i % 2])
        )
    for colour in ("red", "green", "blue"):
        seq.append(
            (
                synthetic.blob_frame(
                    P.width, P.height, colour, cx=P.width / 2, radius=P.height / 4, rng=rng
                ),
                colour,
            )
        )
    seq += [
        (rng.integers(0, 256, (P.height, P.width, 3), dtype=np.uint8), code) for code in range(8)
    ]
    return seq


def expected(seq):
    with get_backend("model", P) as model:
        return [model.process_frame(f, c) for f, c in seq]


@pytest.mark.parametrize("name", COMPILED)
def test_rgb888_frames_are_packed_in_the_loop_bit_for_bit(name):
    seq = frames(1)
    ref = expected(seq)
    with get_backend(name, P) as b:
        # RGB888 frames must not take the host-side packing path at all.
        packed_entry = b._entry_packed
        b._entry_packed = None
        got = [b.process_frame(f, c) for f, c in seq]
        b._entry_packed = packed_entry
        assert got == ref
        assert b.last_loop_seconds > 0
        # The same frames packed on the host first give the same results.
        b.reset()
        assert [b.process_frame(to_rgb444(f, P.width, P.height), c) for f, c in seq] == ref


@pytest.mark.parametrize("name", COMPILED)
def test_rgb888_views_that_are_not_contiguous_are_packed_on_the_host(name):
    seq = [(np.ascontiguousarray(f[:, ::-1]), c) for f, c in frames(2, 4)]
    ref = expected(seq)
    with get_backend(name, P) as b:
        views = [(f[:, ::-1][:, ::-1][:, ::-1], c) for f, c in frames(2, 4)]
        assert not views[0][0].flags.c_contiguous
        assert [b.process_frame(f, c) for f, c in views] == ref


@pytest.mark.parametrize("name", ["model", *COMPILED])
def test_out_receives_the_filtered_frame_every_frame_in_the_same_array(name):
    seq = frames(3, 6)
    ref = expected(seq)
    out = np.full((P.height, P.width), 0xABC, np.uint16)
    address = out.__array_interface__["data"][0]
    with get_backend(name, P) as b:
        for (frame, colour), want in zip(seq, ref, strict=True):
            result = b.process_frame(frame, colour, out=out)
            assert result.filtered is out
            assert out.__array_interface__["data"][0] == address
            assert result == want
        # Without out= each result keeps its own array.
        first = b.process_frame(*seq[0])
        second = b.process_frame(*seq[1])
        assert first.filtered is not second.filtered and first.filtered is not out


@pytest.mark.parametrize("name", ["model", *COMPILED])
@pytest.mark.parametrize(
    "bad, message",
    [
        (np.zeros((16, 41), np.uint16), r"must be a \(16, 40\) uint16 array.*got \(16, 41\)"),
        (np.zeros((16, 40), np.uint8), r"must be a \(16, 40\) uint16 array.*uint8"),
        (np.zeros((16, 40), np.int64), r"must be a \(16, 40\) uint16 array.*int64"),
        (np.zeros((16, 40, 3), np.uint16), r"must be a \(16, 40\) uint16 array"),
        (np.zeros((40, 16), np.uint16).T, "C-contiguous"),
        ([[0] * 40] * 16, "must be a numpy array, not list"),
    ],
)
def test_a_wrong_out_is_a_clear_error_that_changes_nothing(name, bad, message):
    seq = frames(4, 3)
    ref = expected(seq)
    with get_backend(name, P) as b:
        with pytest.raises(FrameError, match=message):
            b.process_frame(*seq[0], out=bad)
        assert b.frames_processed == 0
        assert [b.process_frame(f, c) for f, c in seq] == ref


def test_a_read_only_out_is_refused():
    out = np.zeros((P.height, P.width), np.uint16)
    out.flags.writeable = False
    with get_backend("cxxrtl", P) as b, pytest.raises(FrameError, match="writable"):
        b.process_frame(frames(5, 1)[0][0], out=out)


@pytest.mark.parametrize("name", ["model", "cxxrtl"])
def test_a_greyscale_frame_is_refused_not_read_as_packed_rgb444(name):
    # 192 = 0x0C0 would be the green pixel (0, 12, 0): a grey block "found" as green.
    grey = np.full((P.height, P.width), 50, np.uint8)
    grey[4:12, 10:30] = 192
    with get_backend(name, P) as b:
        with pytest.raises(FrameError, match=r"got uint8 \(16, 40\): a greyscale image\?"):
            b.process_frame(grey, "green")
        assert b.frames_processed == 0


@pytest.mark.parametrize("name", ["model", "cxxrtl"])
def test_a_recorded_numpy_colour_select_runs_as_its_int(name):
    seq = frames(6, 2)[:2]
    ref = expected(seq)
    codes = np.array([4, 2], np.int64)  # a run's color_sel column, red then green
    with get_backend(name, P) as b:
        assert [b.process_frame(f, c) for (f, _), c in zip(seq, codes, strict=True)] == ref
