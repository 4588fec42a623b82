"""``viz.frame_calls``: a frame's direct rerun calls made at its end, with Ctrl-C and SIGTERM
held until they are all made, so a recording never holds a frame in part."""

import signal

import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.viz import frame_calls, open_recorder
from fpga_robotics.viz.frame_calls import FrameCalls, signals_held
from fpga_robotics.viz.readback import read_rrd


class _Stream:
    def __init__(self):
        self.calls = []

    def set_time(self, *args, **kwargs):
        self.calls.append(("set_time", args, kwargs))

    def log(self, *args, **kwargs):
        self.calls.append(("log", args, kwargs))


@pytest.fixture
def python_ctrl_c():
    """Python's own SIGINT handler (KeyboardInterrupt) for the test, whatever an earlier test
    in this process left in force."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_calls_are_made_in_their_order_on_replay_only():
    calls = FrameCalls()
    assert not calls
    calls.set_time("frame", sequence=3)
    calls.log("a", 1, static=True)
    calls.log("b", 2)
    stream = _Stream()
    assert calls and stream.calls == []
    calls.replay(stream)
    assert stream.calls == [
        ("set_time", ("frame",), {"sequence": 3}),
        ("log", ("a", 1), {"static": True}),
        ("log", ("b", 2), {}),
    ]
    assert not calls  # made once


def test_ctrl_c_inside_the_block_takes_effect_at_its_end(python_ctrl_c):
    before = signal.getsignal(signal.SIGINT)
    done = []
    with pytest.raises(KeyboardInterrupt), signals_held():
        signal.raise_signal(signal.SIGINT)
        done.append("the rest of the block")
    assert done == ["the rest of the block"]
    assert signal.getsignal(signal.SIGINT) is before


def test_sigterm_inside_the_block_reaches_the_handler_in_force_at_its_end():
    seen = []
    previous = signal.signal(signal.SIGTERM, lambda n, f: seen.append(n))
    try:
        with signals_held():
            signal.raise_signal(signal.SIGTERM)
            assert seen == []
        assert seen == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_ctrl_c_while_a_frames_rows_are_made_keeps_that_frame_whole(
    tmp_path, monkeypatch, python_ctrl_c
):
    """Ctrl-C between two of frame 3's direct calls (rerun's log runs a good deal of Python,
    so it lands there often): the frame is finished, counted, and the run stops after it."""
    replay = FrameCalls.replay
    frames = {"n": 0}

    def interrupted_replay(self, stream):
        frames["n"] += 1
        if frames["n"] == 4:  # frame 3: Ctrl-C after its first call
            first, rest = self._calls[:1], self._calls[1:]
            self._calls = first
            replay(self, stream)
            signal.raise_signal(signal.SIGINT)
            self._calls = rest
        replay(self, stream)

    monkeypatch.setattr(frame_calls.FrameCalls, "replay", interrupted_replay)
    path = tmp_path / "cut.rrd"
    scenario = load_scenario("divider", ["sim.duration=0.5"])
    with (
        pytest.raises(KeyboardInterrupt),
        open_recorder(f"save:{path}", default_path=str(path)) as rec,
    ):
        run_scenario(scenario, backend="model", recorder=rec)
    data = read_rrd(str(path))
    assert rec.frames_logged == 4
    for entity in ("camera", "world3d/robot", "world3d/people/bodies", "motors/dps", "camera/raw"):
        assert data.entities[entity].frames == [0, 1, 2, 3], entity
