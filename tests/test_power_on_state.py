"""A run starts from the design's power-on state, whatever ran on its backend before: every
register at its initial value, what a reset does not reach (a design without a reset, a
memory) included. Campaigns, mutation judges and forks keep one compiled model per worker and
reset it between runs, so a run that inherited the last one's state would depend on what ran
before it on that worker."""

from pathlib import Path

import numpy as np
import pytest

from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sweep import runner

ROOT = Path(__file__).parent.parent
RANGER = ROOT / "examples" / "verilog_ranger" / "ranger.toml"
COUNTER = ROOT / "tests" / "data" / "frame_counter"


def _differing(a, b):
    """The trajectory columns in which runs ``a`` and ``b`` differ."""
    return [
        k
        for k in a.trajectory
        if not np.array_equal(a.trajectory[k], b.trajectory[k], equal_nan=True)
    ]


@pytest.mark.parametrize("backend", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_a_pin_design_without_reset_runs_the_same_twice_on_one_backend(backend):
    # The ranger has no reset: its 20 ms measuring period starts from its tick register's
    # initial value, so a run that started from the last run's tick would measure (and
    # move) at other instants.
    scenario = load_scenario(str(RANGER), ["sim.duration=1"])
    with make_pin_backend(backend, scenario) as design:
        first, second = (
            run_scenario(scenario, backend=design),
            run_scenario(scenario, backend=design),
        )
    with make_pin_backend(backend, scenario) as fresh:
        expected = run_scenario(scenario, backend=fresh)
    assert _differing(first, expected) == []
    assert _differing(second, expected) == []
    assert np.nanmax(expected.trajectory["x"]) > expected.trajectory["x"][0]  # it moved


@pytest.mark.slow  # Verilog on the frame path: Verilator
def test_a_frame_design_without_reset_counts_its_frames_from_zero_in_every_run():
    # frame_counter drives its wheels at the number of frames it has seen: 1, 2, 3 ... in
    # every run, by hand, not carried on from the run before on the same model.
    argv = [
        "--scenario",
        "follow_person",
        "--duration",
        "1",
        "--backend",
        "verilator",
        "--design",
        f"verilog:{COUNTER / 'frame_counter.v'}",
        "--ports",
        str(COUNTER / "frame_counter_ports.toml"),
    ]
    args, scenario, shadow = runner.load_run(argv)
    design, _ = runner._designs_for(args, scenario, shadow)  # the model a worker keeps
    for _ in range(2):
        left = run_scenario(scenario, backend=design).trajectory["motor_left"]
        assert list(left) == list(range(1, len(left) + 1))


@pytest.mark.parametrize("backend", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_the_compiled_followtarget_frame_backends_repeat_a_run_exactly(backend):
    # With a reset and memories: a second run on the same model is the first again.
    argv = ["--scenario", "follow_person", "--duration", "2", "--backend", backend]
    args, scenario, shadow = runner.load_run(argv)
    design, _ = runner._designs_for(args, scenario, shadow)
    first = run_scenario(scenario, backend=design)
    second = run_scenario(scenario, backend=design)
    assert _differing(first, second) == []
