"""Waveforms on demand from the compiled backends: only the requested frames, every port in
the file, and nothing traced (a different build) when no waveform is asked for."""

import gc
import os
import struct

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import BackendError, WaveformRequest, get_backend
from fpga_robotics.sim.camera import synthetic

PARAMS = FollowTargetParams(
    width=40, height=16, min_pixels=4, proximity_thresholds=(4, 8, 16, 32, 64, 96, 128)
)
PORTS = {
    "clk",
    "rst",
    "pixels__valid",
    "pixels__payload",
    "color_sel",
    "filtered__valid",
    "filtered__payload",
    "frame_done",
    "found",
    "proximity",
    "centroid_x",
    "centroid_leds",
    "motor_left",
    "motor_right",
}


def read_vcd(path):
    """``(names by id code, {id code: [(time, value)]}, [times])`` of a VCD file."""
    names, changes, times = {}, {}, []
    time = None
    in_header = True
    with open(path) as f:
        for line in f:
            tokens = line.split()
            if not tokens:
                continue
            if in_header:
                if tokens[0] == "$var":
                    code, name = tokens[3], tokens[4]
                    names.setdefault(code, set()).add(name)
                elif tokens[0] == "$enddefinitions":
                    in_header = False
                continue
            if tokens[0].startswith("#"):
                time = int(tokens[0][1:])
                times.append(time)
            elif tokens[0][0] in "01xz" and len(tokens) == 1:
                changes.setdefault(tokens[0][1:], []).append((time, tokens[0][0]))
            elif tokens[0][0] == "b" and len(tokens) == 2:
                changes.setdefault(tokens[1], []).append((time, tokens[0][1:]))
    return names, changes, times


def frames():
    rng = np.random.default_rng(5)
    return synthetic.scenario("centre", 40, 16, n_frames=4, rng=rng).frames


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_vcd_holds_the_ports_and_only_the_requested_frames(name, tmp_path):
    path = tmp_path / f"{name}.vcd"
    with get_backend(name, PARAMS, waveform=WaveformRequest(str(path), 1, 2)) as b:
        results = [b.process_frame(f) for f in frames()]
        assert b._library.lib.fr_traced() == 1
    cycles = [r.cycles for r in results]
    names, changes, times = read_vcd(path)
    all_names = set().union(*names.values())
    assert PORTS <= all_names, f"ports missing from the VCD: {PORTS - all_names}"
    # Time counts half clock cycles from construction: frame 0 came before the trace, frames
    # 1 and 2 are in it, frame 3 is not.
    start = 2 * cycles[0] + 1
    assert min(times) >= start
    assert max(times) - min(times) <= 2 * (cycles[1] + cycles[2]) + 2
    assert max(times) - min(times) >= 2 * (cycles[1] + cycles[2]) - 2
    # frame_done pulses once per traced frame.
    code = next(c for c, n in names.items() if "frame_done" in n)
    rises = [t for t, v in changes[code] if v == "1"]
    assert len(rises) == 2
    # The clock rises every two half cycles, frame boundaries included, so the two traced
    # frames' strobes lie as many clock cycles apart as a frame takes.
    clock = next(c for c, n in names.items() if "clk" in n)
    edges = [t for t, v in changes[clock] if v == "1"]
    assert np.diff(edges).tolist() == [2] * (len(edges) - 1)
    assert len(edges) == cycles[1] + cycles[2]
    assert rises[1] - rises[0] == 2 * cycles[1]


def top_port_changes(path):
    """``{port: [(time, value)]}`` of the top module's ports in a VCD file (the scope of its
    first variable), each change once, values as integers."""
    changes, codes, depth, top = {}, {}, 0, None
    time = None
    with open(path) as f:
        for line in f:
            tokens = line.split()
            if not tokens:
                continue
            if tokens[0] == "$scope":
                depth += 1
            elif tokens[0] == "$upscope":
                depth -= 1
            elif tokens[0] == "$var":
                top = depth if top is None else top
                if depth == top and tokens[4] in PORTS:
                    codes.setdefault(tokens[3], []).append(tokens[4])
            elif tokens[0].startswith("#"):
                time = int(tokens[0][1:])
            elif len(tokens) == 1 and tokens[0][0] in "01" and tokens[0][1:] in codes:
                for name in codes[tokens[0][1:]]:
                    changes.setdefault(name, []).append((time, int(tokens[0][0])))
            elif len(tokens) == 2 and tokens[0][0] == "b" and tokens[1] in codes:
                for name in codes[tokens[1]]:
                    changes.setdefault(name, []).append((time, int(tokens[0][1:], 2)))
    deduped = {}
    for name, seq in changes.items():
        kept = []
        for time, value in seq:
            if not kept or kept[-1][1] != value:
                kept.append((time, value))
        deduped[name] = kept
    return deduped


@pytest.mark.slow
def test_cxxrtl_and_verilator_waveforms_show_the_ports_change_at_the_same_times(tmp_path):
    # Both count half clock cycles from construction; an output that follows a flip-flop
    # changes in the half cycle of the edge, on either simulator (CXXRTL computes a port in
    # eval() from the state before the edge, so its traced build settles once more).
    seen = {}
    for name in ("cxxrtl", "verilator"):
        path = tmp_path / f"{name}.vcd"
        with get_backend(name, PARAMS, waveform=WaveformRequest(str(path), 0, 2)) as b:
            for f in frames()[:3]:
                b.process_frame(f)
        seen[name] = top_port_changes(path)
    assert set(seen["cxxrtl"]) == PORTS, set(seen["cxxrtl"]) ^ PORTS
    # frame_done pulses in each of the three frames: the comparison below is not vacuous.
    assert [v for _, v in seen["cxxrtl"]["frame_done"]].count(1) == 3
    for port in sorted(PORTS):
        assert seen["cxxrtl"][port] == seen["verilator"][port], port


@pytest.mark.parametrize("name", ["model", "cxxrtl"])
def test_a_backend_dropped_before_its_last_frame_leaves_no_waveform(name, tmp_path):
    # Frames 0..5 requested, 2 done, then the backend dropped without close() (a script
    # ended by an exception): no half waveform under the real name, no temporary file.
    frame = np.zeros((PARAMS.height, PARAMS.width, 3), np.uint8)
    request = WaveformRequest(str(tmp_path / "w.vcd"), first_frame=0, last_frame=5)
    backend = get_backend(name, PARAMS, waveform=request)
    backend.process_frame(frame)
    backend.process_frame(frame)
    del backend
    gc.collect()
    assert os.listdir(tmp_path) == []
    # close() writes out the frames done so far, as before.
    with get_backend(name, PARAMS, waveform=request) as backend:
        backend.process_frame(frame)
    assert os.listdir(tmp_path) == ["w.vcd"]


def test_untraced_build_has_no_tracing():
    with get_backend("cxxrtl", PARAMS) as b:
        assert b._library.lib.fr_traced() == 0
        assert b.variant == "plain"


def test_waveform_format_and_range_errors(tmp_path):
    with pytest.raises(BackendError, match=r"\.vcd waveforms only.*verilator backend for \.fst"):
        get_backend("cxxrtl", PARAMS, waveform=WaveformRequest(str(tmp_path / "w.fst")))
    with pytest.raises(BackendError, match=r"\.vcd/\.fst waveforms only"):
        get_backend("verilator", PARAMS, waveform=WaveformRequest(str(tmp_path / "w.ghw")))
    with pytest.raises(BackendError, match="before its first_frame"):
        get_backend("cxxrtl", PARAMS, waveform=WaveformRequest(str(tmp_path / "w.vcd"), 3, 1))
    with pytest.raises(BackendError, match="no directory"):
        get_backend("cxxrtl", PARAMS, waveform=WaveformRequest(str(tmp_path / "no" / "w.vcd")))
    # Frames are counted from 0: a negative or fractional one would never be traced.
    for first, last in ((-5, -2), (-1, 1), (1.5, 3)):
        for backend in ("model", "cxxrtl"):
            with pytest.raises(BackendError, match="must be a frame number"):
                get_backend(
                    backend, PARAMS, waveform=WaveformRequest(str(tmp_path / "w.vcd"), first, last)
                )
    with pytest.raises(BackendError, match=r"\.vcd waveforms only.*verilator backend for \.fst"):
        get_backend("model", PARAMS, waveform=WaveformRequest(str(tmp_path / "w.fst")))


@pytest.mark.slow
def test_verilator_fst(tmp_path):
    path = tmp_path / "v.fst"
    try:
        b = get_backend("verilator", PARAMS, waveform=WaveformRequest(str(path), 0, 1))
    except BackendError as exc:
        if "lz4" in str(exc):
            pytest.skip(str(exc))
        raise
    with b:
        for f in frames()[:3]:
            b.process_frame(f)
    data = path.read_bytes()
    # An FST file is a sequence of blocks: type byte, then a big-endian length that counts
    # itself; the first is the header block (type 0).
    assert data[0] == 0
    offset, types = 0, []
    while offset < len(data):
        types.append(data[offset])
        (length,) = struct.unpack(">Q", data[offset + 1 : offset + 9])
        assert length >= 8
        offset += 1 + length
    assert offset == len(data)
    assert 1 in types or 5 in types or 8 in types  # a value-change block
