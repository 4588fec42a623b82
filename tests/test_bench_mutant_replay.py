"""``fpga-robotics bench mutant_replay``: the mutant netlist's replay against its full run."""

from types import SimpleNamespace

import numpy as np
import pytest

from fpga_robotics.bench import mutant_replay
from fpga_robotics.cli.errors import UsageError


class CountingDesign:
    def __init__(self):
        self.resets, self.frames = 0, []

    def reset(self):
        self.resets += 1

    def process_frame(self, rgb, color):
        self.frames.append((int(rgb[0, 0, 0]), color))


def test_replay_feeds_every_recorded_frame_after_a_reset_each_time():
    seen = [(np.full((2, 2, 3), k, np.uint8), k % 3) for k in range(5)]
    design = CountingDesign()
    ms = mutant_replay.replay_ms(design, seen, repeats=2)
    assert design.resets == 2
    assert design.frames == [(k, k % 3) for k in range(5)] * 2
    assert ms >= 0.0


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--mutants", "0"], "--mutants must be in 1..1000"),
        (["--duration", "0"], "--duration must be in"),
        (["--resolution", "12"], "--resolution: resolution must look like WIDTHxHEIGHT"),
        # Yosys reads the seed into a C int: 2**32 + 1 would give seed 1's mutants.
        (["--seed", str(2**32 + 1)], "--seed must be 0..2147483647"),
    ],
)
def test_bad_arguments_are_usage_errors(argv, message):
    with pytest.raises(UsageError, match=message):
        mutant_replay.main(argv)


@pytest.mark.slow  # Verilator and CXXRTL builds
def test_the_full_run_costs_more_than_its_netlist_alone(capsys):
    args = SimpleNamespace(
        scenario="follow_person", resolution="160x120", duration=1.0, mutants=4, seed=0, repeats=1
    )
    figures = mutant_replay.run(args)
    assert figures["frames"] == 30
    # The full run is the netlist's frames plus the world's: more than the netlist alone.
    assert figures["full_ms"] > figures["netlist_ms"] > 0
    assert figures["fork_ceiling"] == pytest.approx(figures["full_ms"] / figures["netlist_ms"])
    assert figures["watched_ms"] > 0
    out = capsys.readouterr().out
    assert "forking gains at most" in out and "with its watch output watched" in out
