"""The ``model`` backend: frame API, state across frames, cycle accounting, VCD of the ports."""

import os

import numpy as np
import pytest
from vcd.reader import TokenKind, tokenize

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends.base import (
    BackendError,
    DesignBackend,
    FrameResult,
    WaveformRequest,
)
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.backends.model_waveform import CLOCK_PERIOD_NS
from fpga_robotics.sim.camera import synthetic
from fpga_robotics.sim.camera.frames import FrameError
from fpga_robotics.sim.models.follow_target import FollowTargetModel


class _Latencies(FollowTargetParams):
    """Parameters with chosen latencies, so that cycle counts can be computed by hand."""

    result_latency = 5
    motor_latency = 2
    filter_latency = 3


def _small(**kw):
    # 48x16: window columns 4..43 (5 columns a bin), rows 1..14; count thresholds by hand.
    base = {"width": 48, "height": 16, "min_pixels": 20, "lost_frames": 3}
    base.update(kw)
    return _Latencies(**base)


def test_is_a_design_backend_named_model():
    backend = ModelBackend()
    assert isinstance(backend, DesignBackend)
    assert backend.name == ModelBackend.name == "model"


def test_results_are_the_models_and_state_persists_across_frames():
    params = FollowTargetParams(lost_frames=4)
    sc = synthetic.scenario("lost", lost_frames=4, n_frames=3, rng=5)
    backend = ModelBackend(params)
    model = FollowTargetModel(params)
    results = [backend.process_frame(f, "red") for f in sc.frames]
    for frame, result in zip(sc.frames, results):
        expected = model.process(synthetic.as_rgb444(frame), "red")
        assert isinstance(result, FrameResult)
        assert np.array_equal(result.filtered, expected.filtered)
        t = expected.tracker
        assert result.outputs()[:6] == (
            t.found,
            t.proximity,
            t.centroid_x,
            t.centroid_leds,
            expected.motor_left,
            expected.motor_right,
        )
    motors = [(r.motor_left, r.motor_right) for r in results]
    # 3 seen at the right, 3 lost frames holding, 4 searching right, then the left target.
    assert motors[3:6] == [motors[2]] * 3
    assert motors[6:10] == [(250, -250)] * 4
    assert motors[10][0] < motors[10][1]
    assert backend.frames_processed == len(sc.frames)


def test_reset_restores_the_power_on_state():
    sc = synthetic.scenario("lost", lost_frames=15, n_frames=2, rng=6)
    backend = ModelBackend()
    first = [backend.process_frame(f, "red") for f in sc.frames]
    backend.reset()
    assert backend.frames_processed == 0
    # Lost right after reset: the outputs stay 0 (not the last command before reset).
    blank = backend.process_frame(synthetic.empty_frame(160, 120, rng=1), "red")
    assert (blank.motor_left, blank.motor_right, blank.found) == (0, 0, False)
    backend.reset()
    again = [backend.process_frame(f, "red") for f in sc.frames]
    assert again == first


@pytest.mark.parametrize(
    "line_blank,frame_blank,cycles",
    [
        # 16 lines of 48 pixels: P = 768, P + 5 + 2 = 775 > 768.
        (0, 0, 775),
        (0, 7, 775),
        (0, 8, 776),  # frame blanking dominates: 768 + 8
        # line_blank 3: input 16 * 51 = 816 cycles, P = 813, 813 + 7 = 820 > 816.
        (3, 0, 820),
        (3, 4, 820),
        (3, 10, 826),
    ],
)
def test_cycles_follow_the_documented_accounting(line_blank, frame_blank, cycles):
    backend = ModelBackend(_small(), line_blank=line_blank, frame_blank=frame_blank)
    result = backend.process_frame(np.zeros((16, 48), np.uint16))
    assert result.cycles == cycles


def test_cycles_use_the_params_latencies():
    p = FollowTargetParams()
    result = ModelBackend(p, line_blank=2).process_frame(np.zeros((120, 160, 3), np.uint8))
    assert result.cycles == max(120 * 162, 120 * 162 - 2 + p.result_latency + p.motor_latency)


@pytest.mark.parametrize(
    "frame,message",
    [
        (np.zeros((120, 160, 3), np.uint8), r"shape \(16, 48, 3\)"),
        (np.zeros((16, 48, 3), np.float64), "uint8"),
        (np.zeros((16, 48), np.int16), "unsigned"),
        (np.full((16, 48), 0x1000, np.uint16), "0xFFF"),
    ],
)
def test_bad_frames_raise_frame_error(frame, message):
    backend = ModelBackend(_small())
    with pytest.raises(FrameError, match=message):
        backend.process_frame(frame)
    assert backend.frames_processed == 0


def test_bad_colour_is_a_value_error():
    with pytest.raises(ValueError, match="unknown colour"):
        ModelBackend(_small()).process_frame(np.zeros((16, 48), np.uint16), "purple")


# Waveforms -------------------------------------------------------------------------------


def _read_vcd(path):
    """{name: (times, values)} of every variable of the trace, and the end time."""
    ids, changes, now = {}, {}, 0
    with open(path, "rb") as f:
        for tok in tokenize(f):
            if tok.kind is TokenKind.VAR:
                ids[tok.var.id_code] = tok.var.reference
                changes[tok.var.reference] = []
            elif tok.kind is TokenKind.CHANGE_TIME:
                now = tok.time_change
            elif tok.kind in (TokenKind.CHANGE_SCALAR, TokenKind.CHANGE_VECTOR):
                changes[ids[tok.data.id_code]].append((now, int(tok.data.value)))
    return {
        name: (np.array([t for t, _ in c]), np.array([v for _, v in c]))
        for name, c in changes.items()
    }, now


def _sample(trace, name, edge):
    """Value of ``name`` sampled by the rising clock edge ``edge`` (just before it)."""
    times, values = trace[name]
    i = np.searchsorted(times, edge * CLOCK_PERIOD_NS, side="left") - 1
    return int(values[i])


def test_waveform_shows_the_ports_cycle_by_cycle(tmp_path):
    params = _small()
    line_blank, frame_blank = 2, 9
    right = synthetic.TargetState(True, 36, 8, 4)  # 49 pixels, found (min_pixels 20)
    left = synthetic.TargetState(True, 12, 8, 4)
    gone = synthetic.TargetState(False)
    states = [right] * 2 + [gone] * 4 + [left] * 2
    frames = [synthetic.as_rgb444(f) for f in synthetic.sequence(48, 16, states, rng=8)]
    path = tmp_path / "trace.vcd"
    request = WaveformRequest(str(path), first_frame=1, last_frame=5)
    backend = ModelBackend(params, line_blank=line_blank, frame_blank=frame_blank, waveform=request)
    results = []
    for i, frame in enumerate(frames[:6]):
        results.append(backend.process_frame(frame, "red"))
        # The file appears complete, once the last requested frame is done.
        assert path.exists() == (i >= 5)
    assert sorted(os.listdir(tmp_path)) == ["trace.vcd"]
    trace, end = _read_vcd(path)
    assert set(trace) >= {
        "clk", "rst", "pixels__valid", "pixels__payload", "color_sel", "filtered__valid",
        "filtered__payload", "frame_done", "found", "proximity", "centroid_x",
        "centroid_leds", "motor_left", "motor_right",
    }  # fmt: skip
    cycles = results[0].cycles
    assert cycles == max(16 * 50 + 9, 16 * 50 - 2 + 7)
    rises = trace["clk"][0][trace["clk"][1] == 1]
    assert list(rises) == [k * CLOCK_PERIOD_NS for k in range(1, 5 * cycles + 1)]
    p_edge = 16 * 50 - 2
    previous = results[0]
    for n in range(5):
        frame, result, base = frames[n + 1], results[n + 1], n * cycles
        flags = np.zeros((16, 48), int)
        flags[0, 0] |= 1 << 12
        flags[:, 47] |= 1 << 13
        sent, got = [], []
        for k in range(1, cycles + 1):
            if _sample(trace, "pixels__valid", base + k):
                sent.append((k, _sample(trace, "pixels__payload", base + k)))
            if _sample(trace, "filtered__valid", base + k):
                got.append((k, _sample(trace, "filtered__payload", base + k)))
        expected_edges = [y * 50 + x + 1 for y in range(16) for x in range(48)]
        assert [k for k, _ in sent] == expected_edges
        assert [v for _, v in sent] == list((frame | flags).ravel())
        assert [k for k, _ in got] == [k + 3 for k in expected_edges]
        assert [v for _, v in got] == list((result.filtered | flags).ravel())
        assert _sample(trace, "color_sel", base + 1) == 0b100
        done = [k for k in range(1, cycles + 1) if _sample(trace, "frame_done", base + k)]
        # High in the cycle right after edge P + 5: sampled by the edge after it.
        assert done == [p_edge + 5 + 1]
        for name, new, old, at in (
            ("found", result.found, previous.found, p_edge + 5),
            ("centroid_x", result.centroid_x, previous.centroid_x, p_edge + 5),
            ("centroid_leds", result.centroid_leds, previous.centroid_leds, p_edge + 5),
            ("proximity", result.proximity, previous.proximity, p_edge + 5),
            ("motor_left", result.motor_left & 0xFFFF, previous.motor_left & 0xFFFF, p_edge + 7),
            ("motor_right", result.motor_right & 0xFFFF, previous.motor_right & 0xFFFF, p_edge + 7),
        ):
            assert _sample(trace, name, base + at) == int(old), (n, name)
            assert _sample(trace, name, base + at + 1) == int(new), (n, name)
        previous = result
    # Traced: seen at the right, two lost frames holding, then the search to the right.
    assert [r.found for r in results[1:6]] == [True, False, False, False, False]
    assert [r.motor_left for r in results[3:6]] == [results[1].motor_left, 250, 250]
    assert end >= 5 * cycles * CLOCK_PERIOD_NS


def test_waveform_is_written_at_reset_or_close_with_the_frames_done(tmp_path):
    frame = np.zeros((16, 48), np.uint16)
    path = tmp_path / "a.vcd"
    backend = ModelBackend(_small(), waveform=WaveformRequest(str(path), 0, 10))
    backend.process_frame(frame)
    assert not path.exists()
    backend.reset()
    assert path.exists()
    trace, _ = _read_vcd(path)
    assert int(trace["frame_done"][1].sum()) == 1
    path2 = tmp_path / "b.vcd"
    with ModelBackend(_small(), waveform=WaveformRequest(str(path2), 1, 1)) as b2:
        b2.process_frame(frame)
        assert not path2.exists()  # frame 0 is not requested
    assert not path2.exists()  # nothing requested was run: nothing written
    assert os.listdir(tmp_path) == ["a.vcd"]


@pytest.mark.parametrize(
    "path,message",
    [
        ("trace.fst", r"\.vcd waveforms only"),
        ("missing/dir/trace.vcd", "no directory"),
    ],
)
def test_bad_waveform_requests_are_backend_errors(tmp_path, path, message):
    with pytest.raises(BackendError, match=message):
        ModelBackend(_small(), waveform=WaveformRequest(str(tmp_path / path)))
