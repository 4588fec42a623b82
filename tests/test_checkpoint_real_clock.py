"""World checkpoints in real-clock timing: a run restored at a middle frame, its pin design
brought there by its journal, continues bit for bit as the uninterrupted run, on every
shipped real-clock scenario (the connectors' state and the wheels' delay queue included)."""

import pytest
from run_equality import assert_same_run

from fpga_robotics.loop import checkpoint
from fpga_robotics.loop.pin_journal import JournalPins, replay
from fpga_robotics.loop.real_clock import RealClockLoop, make_pin_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario, shipped_scenarios

REAL_CLOCK = [n for n in shipped_scenarios() if load_scenario(n).sim.timing == "real_clock"]


def test_there_are_real_clock_scenarios():
    assert {"line_track", "obstacle_between"} <= set(REAL_CLOCK)


@pytest.mark.parametrize("name", REAL_CLOCK)
def test_restored_run_is_the_uninterrupted_run(name):
    # Long enough for the ultrasound to measure several times and the wheels to turn.
    s = load_scenario(name, ["sim.duration=1.2"])
    with make_pin_backend("cxxrtl", s) as design:
        full = run_scenario(s, backend=design)

        # The same run, stopped at a middle frame to take a checkpoint, then run on.
        design.reset()
        journal = JournalPins(design)
        loop = RealClockLoop(s, design=journal)
        middle = loop.n_frames // 2
        for k in range(middle):
            loop.run_frame(k)
        saved = checkpoint.take(loop)
        assert saved.frame == middle and saved.design_calls == len(journal.calls) > 0
        calls, cycle = journal.calls[: saved.design_calls], journal.cycle
        assert cycle > 0
        assert_same_run(loop.run(start=middle), full)

    # A loop that has run elsewhere (its own frames), restored, with a fresh design brought
    # to the checkpoint by the journal, continues exactly as the full run; twice over (the
    # checkpoint is left as it was).
    for _ in range(2):
        with make_pin_backend("cxxrtl", s) as other, make_pin_backend("cxxrtl", s) as design:
            other.reset()
            resumed = RealClockLoop(s, design=other)
            for k in range(3):
                resumed.run_frame(k)
            checkpoint.restore(resumed, saved)
            resumed.use_design(replay(design, calls))
            assert design.cycle == cycle
            assert_same_run(resumed.run(start=middle), full)
