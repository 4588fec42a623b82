"""The ``pysim`` backend against the ``model`` backend: every output, the filtered frame and the
cycle count (which checks the documented latencies), state across frames, reset, blanking,
waveforms of chosen frames only, and the frame_done watchdog."""

import gc
import os

import numpy as np
import pytest
from amaranth import Module
from hwsim import small_params
from vcd.reader import TokenKind, tokenize

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.top import FollowTarget
from fpga_robotics.sim.backends.base import BackendError, WaveformRequest
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.backends.pysim import PERIOD, PysimBackend
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import FrameError


def sequence(p, seed, n_lost=None):
    """(frame, colour) pairs: targets, then enough empty frames to search, random frames."""
    rng = np.random.default_rng(seed)
    out = []
    for colour, cx in (("red", p.width * 0.8), ("blue", p.width * 0.2), ("white", p.width / 2)):
        out.append(
            (
                synthetic.blob_frame(
                    p.width, p.height, colour, cx=cx, radius=p.height / 3, rng=rng
                ),
                colour,
            )
        )
    for _ in range(p.lost_frames + 1 if n_lost is None else n_lost):
        out.append((synthetic.empty_frame(p.width, p.height, rng=rng), "red"))
    out.append((synthetic.random_frame(p.width, p.height, rng=rng), "none"))
    out.append((synthetic.random_frame(p.width, p.height, rng=rng), "cyan"))
    return out


@pytest.mark.parametrize("line_blank,frame_blank", [(0, 0), (3, 5), (0, 400)])
def test_frames_match_the_model_backend(line_blank, frame_blank):
    p = small_params()
    frames = sequence(p, seed=line_blank + frame_blank)
    with (
        PysimBackend(p, line_blank=line_blank, frame_blank=frame_blank) as sim,
        ModelBackend(p, line_blank=line_blank, frame_blank=frame_blank) as model,
    ):
        for frame, colour in frames:
            got, want = sim.process_frame(frame, colour), model.process_frame(frame, colour)
            assert got.outputs() == want.outputs()
            assert np.array_equal(got.filtered, want.filtered)
            assert got.filtered.dtype == np.uint16 and got.filtered.shape == (p.height, p.width)


def test_reset_returns_to_the_power_on_state():
    p = small_params(lost_frames=2)
    frames = sequence(p, seed=9)
    with PysimBackend(p) as sim, ModelBackend(p) as model:
        for frame, colour in frames[:4]:
            sim.process_frame(frame, colour)
            model.process_frame(frame, colour)
        sim.reset()
        model.reset()
        assert sim.frames_processed == 0
        for frame, colour in frames[4:]:
            assert sim.process_frame(frame, colour) == model.process_frame(frame, colour)


def test_packed_and_rgb888_frames_give_the_same_result():
    p = small_params()
    frame, colour = sequence(p, seed=2)[0]
    with PysimBackend(p) as a, PysimBackend(p) as b:
        assert a.process_frame(frame, colour) == b.process_frame(synthetic.as_rgb444(frame), colour)


def test_wrong_frame_shape_is_a_clear_error():
    p = small_params()
    with PysimBackend(p) as sim, pytest.raises(FrameError, match="shape"):
        sim.process_frame(np.zeros((p.height + 1, p.width, 3), np.uint8))


def test_full_size_frame_matches_the_model():
    p = FollowTargetParams()
    rng = np.random.default_rng(1)
    frame = synthetic.blob_frame(160, 120, "magenta", cx=30, cy=70, radius=22, rng=rng)
    with PysimBackend(p, line_blank=2) as sim, ModelBackend(p, line_blank=2) as model:
        got, want = sim.process_frame(frame, "magenta"), model.process_frame(frame, "magenta")
    assert got == want and got.found


def vcd_times_and_names(path):
    times, names = [], set()
    with open(path, "rb") as f:
        for token in tokenize(f):
            if token.kind is TokenKind.CHANGE_TIME:
                times.append(token.time_change)
            elif token.kind is TokenKind.VAR:
                names.add(token.var.reference)
    return times, names


def test_waveform_covers_only_the_requested_frames(tmp_path):
    p = small_params()
    frames = sequence(p, seed=4)[:4]
    path = tmp_path / "frames_1_2.vcd"
    request = WaveformRequest(str(path), first_frame=1, last_frame=2)
    with (
        PysimBackend(p, line_blank=1, waveform=request) as traced,
        PysimBackend(p, line_blank=1) as plain,
    ):
        results = []
        for i, (frame, colour) in enumerate(frames):
            results.append(traced.process_frame(frame, colour))
            assert results[-1] == plain.process_frame(frame, colour)
            if i == 1:
                assert not path.exists()  # written under a temporary name until complete
            if i == 2:
                assert path.exists()  # complete once the last requested frame is done
        size_after_frame_2 = path.stat().st_size
    assert path.stat().st_size == size_after_frame_2  # frame 3 was not traced
    assert sorted(os.listdir(tmp_path)) == [path.name]  # no temporary file left
    assert path.stat().st_mode & 0o077 != 0  # a normal file, not mkstemp's private 0600
    times, names = vcd_times_and_names(path)
    assert {"frame_done", "pixels__payload", "motor_left", "centroid_x"} <= names
    # Rising edge n of the simulation is at (n - 1/2) periods; frame 1 starts after the last
    # edge of frame 0 and frame 2 ends with edge c0 + c1 + c2 (plus the clock's next fall).
    fs = round(PERIOD * 1e15)
    c0, c1, c2 = (r.cycles for r in results[:3])
    changes = [t for t in times if t > 0]  # time 0 holds the values dumped at the start
    assert min(changes) > (c0 - 0.5) * fs
    assert max(changes) <= (c0 + c1 + c2 + 0.5) * fs
    assert max(changes) >= (c0 + c1 + c2 - 0.5) * fs


def vcd_changes(path):
    """``(id code by name, [(time, id code, value)])`` of a VCD (the first id of a name)."""
    ids, changes, time = {}, [], None
    with open(path, "rb") as f:
        for token in tokenize(f):
            if token.kind is TokenKind.VAR:
                ids.setdefault(token.var.reference, token.var.id_code)
            elif token.kind is TokenKind.CHANGE_TIME:
                time = token.time_change
            elif token.kind is TokenKind.CHANGE_SCALAR:
                changes.append((time, token.scalar_change.id_code, token.scalar_change.value))
            elif token.kind is TokenKind.CHANGE_VECTOR:
                changes.append((time, token.vector_change.id_code, token.vector_change.value))
    return ids, changes


def test_waveform_starts_with_the_state_at_the_window_start_and_holds_its_edges(tmp_path):
    p = small_params()
    frames = sequence(p, seed=6)[:3]
    path = tmp_path / "frame_1.vcd"
    with PysimBackend(p, line_blank=2, waveform=WaveformRequest(str(path), 1, 1)) as sim:
        results = [sim.process_frame(frame, colour) for frame, colour in frames]
    fs = round(PERIOD * 1e15)
    c0, c1 = results[0].cycles, results[1].cycles
    ids, changes = vcd_changes(path)
    dump = {code: value for time, code, value in changes if time == 0}
    # The initial dump holds the state right after frame 0's last edge.
    assert dump[ids["clk"]] == "1"
    assert dump[ids["frame_done"]] == "0"
    assert dump[ids["centroid_x"]] == results[0].centroid_x
    assert dump[ids["proximity"]] == results[0].proximity
    assert dump[ids["found"]] == str(int(results[0].found))
    # Frame 1 starts a quarter period after that edge; every one of its edges is in the file,
    # the last is frame 1's last; the file ends when frame 2 would start.
    times = sorted({time for time, _, _ in changes if time > 0})
    assert times[0] == (c0 - 0.25) * fs
    rising = [
        time for time, code, value in changes if time > 0 and code == ids["clk"] and value == "1"
    ]
    assert rising == [(c0 + k - 0.5) * fs for k in range(1, c1 + 1)]
    with open(path) as f:
        assert f.read().rstrip().endswith(f"#{round((c0 + c1 - 0.25) * fs)}")


def test_a_reset_before_the_window_is_counted_and_one_inside_ends_it(tmp_path):
    p = small_params()
    frames = sequence(p, seed=7)[:3]
    fs = round(PERIOD * 1e15)
    before, inside = tmp_path / "before.vcd", tmp_path / "inside.vcd"
    with PysimBackend(p, waveform=WaveformRequest(str(before), 1, 1)) as sim:
        c0 = sim.process_frame(*frames[0]).cycles
        sim.reset()  # one edge; the frames count from 0 again
        c0b = sim.process_frame(*frames[1]).cycles
        assert not before.exists()
        sim.process_frame(*frames[2])
        assert before.exists()
    _, changes = vcd_changes(before)
    first = min(time for time, _, _ in changes if time > 0)
    assert first == (c0 + 1 + c0b - 0.25) * fs
    with PysimBackend(p, waveform=WaveformRequest(str(inside), 0, 5)) as sim:
        c0 = sim.process_frame(*frames[0]).cycles
        sim.reset()
        assert inside.exists()  # the window ended with the frame before the reset
        size = inside.stat().st_size
        sim.process_frame(*frames[1])
    assert inside.stat().st_size == size
    _, changes = vcd_changes(inside)
    assert max(time for time, _, _ in changes) <= (c0 - 0.5) * fs
    assert sorted(os.listdir(tmp_path)) == ["before.vcd", "inside.vcd"]


def _interrupt_the_third_frame(p, path):
    """Frames 0 and 1 and part of 2 of a backend tracing 1..3, then Ctrl-C (as
    ``KeyboardInterrupt`` from inside the simulation)."""
    frame, colour = sequence(p, seed=8)[0]
    with (
        pytest.raises(KeyboardInterrupt),
        PysimBackend(p, waveform=WaveformRequest(str(path), 1, 3)) as sim,
    ):
        sim.process_frame(frame, colour)
        sim.process_frame(frame, colour)
        calls = iter(range(50))
        advance = sim._sim.advance

        def interrupted():
            if next(calls, None) is None:
                raise KeyboardInterrupt
            return advance()

        sim._sim.advance = interrupted
        sim.process_frame(frame, colour)


# Amaranth cannot close a testbench stopped inside ``tick().repeat()`` without an error,
# reported as unraisable when the dropped simulator is collected.
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_an_interrupted_simulation_leaves_no_temporary_file(tmp_path):
    path = tmp_path / "w.vcd"
    _interrupt_the_third_frame(small_params(), path)
    gc.collect()  # here, not in a later test
    # close() wrote the window as far as it got; nothing else is left.
    assert os.listdir(tmp_path) == ["w.vcd"]
    assert "frame_done" in vcd_times_and_names(path)[1]


def test_an_interrupted_trim_leaves_no_file_at_all(tmp_path, monkeypatch):
    from fpga_robotics.sim.backends import pysim

    def interrupted_trim(src, dst, *args, **kwargs):
        dst.write(src.read(100))
        raise KeyboardInterrupt

    monkeypatch.setattr(pysim, "trim_vcd", interrupted_trim)
    p = small_params()
    frame, colour = sequence(p, seed=8)[0]
    with (
        pytest.raises(KeyboardInterrupt),
        PysimBackend(p, waveform=WaveformRequest(str(tmp_path / "w.vcd"), 0, 0)) as sim,
    ):
        sim.process_frame(frame, colour)
    assert os.listdir(tmp_path) == []


def test_a_window_never_reached_leaves_no_file(tmp_path):
    p = small_params()
    frame, colour = sequence(p, seed=8)[0]
    with PysimBackend(p, waveform=WaveformRequest(str(tmp_path / "w.vcd"), 2, 3)) as sim:
        sim.process_frame(frame, colour)
        assert len(os.listdir(tmp_path)) == 1  # the recording, from time 0
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("path,message", [("wave.fst", ".vcd"), ("missing/wave.vcd", "directory")])
def test_bad_waveform_requests_are_clear_errors(tmp_path, path, message):
    with pytest.raises(BackendError, match=message):
        PysimBackend(small_params(), waveform=WaveformRequest(str(tmp_path / path)))


class _NeverDone(FollowTarget):
    """A broken design: filters nothing and never strobes frame_done."""

    def elaborate(self, platform):
        m = Module()
        # The parts exist but are left unconnected: frame_done stays 0.
        m.submodules += [self.color_filter, self.tracker, self.motor]
        m.d.sync += [
            self.filtered.valid.eq(self.pixels.valid),
            self.filtered.payload.eq(self.pixels.payload),
        ]
        return m


def test_a_hung_design_fails_with_a_backend_error(monkeypatch):
    from fpga_robotics.sim.backends import pysim

    monkeypatch.setattr(pysim, "FollowTarget", _NeverDone)
    p = small_params()
    frame, colour = sequence(p, seed=1)[0]
    with PysimBackend(p) as sim:
        with pytest.raises(BackendError, match="frame_done did not come"):
            sim.process_frame(frame, colour)
        # The watchdog leaves the simulator usable: the next call fails the same way.
        with pytest.raises(BackendError, match="frame_done did not come"):
            sim.process_frame(frame, colour)


def test_an_unfinished_waveform_leaves_no_file_behind(tmp_path):
    p = small_params()
    frame, colour = sequence(p, seed=3)[0]
    sim = PysimBackend(p, waveform=WaveformRequest(str(tmp_path / "w.vcd"), 0, 5))
    sim.process_frame(frame, colour)
    assert len(os.listdir(tmp_path)) == 1 and not (tmp_path / "w.vcd").exists()
    del sim  # dropped before the last requested frame, without close()
    gc.collect()
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize(
    "size",
    [
        (320, 240),
        pytest.param((640, 480), marks=pytest.mark.slow),
    ],
)
def test_larger_geometries_match_the_model(size):
    w, h = size
    p = FollowTargetParams(width=w, height=h)
    rng = np.random.default_rng(w)
    frame = synthetic.blob_frame(w, h, "yellow", cx=w * 0.7, cy=h / 2, radius=h / 4, rng=rng)
    with PysimBackend(p) as sim, ModelBackend(p) as model:
        got, want = sim.process_frame(frame, "yellow"), model.process_frame(frame, "yellow")
    assert got == want and got.found and got.centroid_x > w // 2
