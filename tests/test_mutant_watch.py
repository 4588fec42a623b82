"""The mutant netlist's watch output (sim.mutant_watch): the frame each mutant first acts in,
recorded by a reference run at ``mutsel = 0``, against each mutant simulated on its own.

A mutant whose bit never rises must give the design's outputs and filtered image on every
frame; a mutant whose outputs first differ at frame ``d`` must have acted at ``d`` or
before. Both are checked against every mutant of a seed, each replayed alone on the frames
the reference saw. Then the forked run of a mutant that never acts, made without running its
design, against its full run."""

import re
from pathlib import Path

import numpy as np
import pytest
from run_equality import assert_same_run
from toolchains import needs_mutation_toolchain

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim import mutation
from fpga_robotics.sim.backends import BackendError
from fpga_robotics.sim.backends.port_map import PortMapError, check_widths, parse_port_map
from fpga_robotics.sim.mutant_watch import WATCH_PORT, add_watch

PARAMS = FollowTargetParams(width=80, height=60)

# A module as Yosys writes it after ``mutate -ctrl sel 2 1`` and ``2``: two select muxes,
# the second with a constant faulty side, and an unrelated mux.
_RTLIL = r"""module \top
  wire width 2 input 1 \sel
  wire input 2 \a
  wire output 3 \y
  wire width 2 output 4 \z
  wire $eq1
  wire $eq2
  wire $inv
  cell $eq $e1
    parameter \A_WIDTH 2
    connect \A \sel
    connect \B 2'01
    connect \Y $eq1
  end
  cell $mux $m1
    parameter \WIDTH 1
    connect \A \a
    connect \B $inv
    connect \S $eq1
    connect \Y \y
  end
  cell $eq $e2
    parameter \A_WIDTH 2
    connect \A \sel
    connect \B 2'10
    connect \Y $eq2
  end
  cell $mux $m2
    parameter \WIDTH 1
    connect \A \z [1]
    connect \B 1'1
    connect \S $eq2
    connect \Y \z [0]
  end
  cell $mux $other
    parameter \WIDTH 1
    connect \A \a
    connect \B \z [1]
    connect \S \a
    connect \Y $inv
  end
end
"""


def _cells(text):
    return re.findall(r"cell \$xor (\S+)\n(.*?)\n  end", text, re.DOTALL)


def test_each_select_mux_gets_the_xor_of_its_two_sides():
    out = add_watch(_RTLIL, "top", "sel", 2)
    assert "  wire width 2 output 5 \\mutinf\n" in out
    cells = {name: dict(re.findall(r"connect \\(\w) (.+)", body)) for name, body in _cells(out)}
    assert cells == {
        "$fr_watch$1": {"A": "\\a", "B": "$inv", "Y": "\\mutinf [0]"},
        "$fr_watch$2": {"A": "\\z [1]", "B": "1'1", "Y": "\\mutinf [1]"},
    }
    assert out.rstrip().endswith("end")


def test_a_mutant_whose_mux_is_missing_acts_from_the_start():
    out = add_watch(_RTLIL, "top", "sel", 3)  # no mutant 3 in the module
    assert "connect \\mutinf [2] 1'1" in out
    assert len(_cells(out)) == 2


def test_the_port_map_watch_must_name_an_output():
    base = {
        "top": "t",
        "clock": {"port": "clk"},
        "pixels": {"valid": "v", "payload": "p"},
        "result": {"strobe": "done"},
        "outputs": {"motor_left": "ml"},
    }
    assert parse_port_map({**base, "watch": {"port": "w"}}).watch == "w"
    assert parse_port_map(base).watch is None
    with pytest.raises(PortMapError, match="watch"):
        parse_port_map({**base, "watch": {"prt": "w"}})
    with pytest.raises(PortMapError, match="mapped more than once"):
        parse_port_map({**base, "watch": {"port": "ml"}})
    # Against the design's ports: the watched port must exist and be an output.
    watching = parse_port_map({**base, "watch": {"port": "w"}})
    ports = {"clk": ("input", 1, False), "v": ("input", 1, False), "p": ("input", 14, False)}
    ports |= {"done": ("output", 1, False), "ml": ("output", 16, True)}
    check_widths(watching, {**ports, "w": ("output", 60, False)})  # any width
    for bad in ({}, {"w": ("input", 60, False)}):
        with pytest.raises(PortMapError, match="watch.port 'w' must be an output"):
            check_widths(watching, {**ports, **bad})


def _outputs(result):
    return (result.outputs(), result.filtered.copy())


@needs_mutation_toolchain
@pytest.mark.slow  # builds the mutants' Verilator model
def test_the_watch_bounds_where_every_mutant_of_a_seed_first_differs(tmp_path):
    from fpga_robotics.loop.fork import ReferenceRun
    from fpga_robotics.mutation.design import (
        WATCH_PORTS_NAME,
        open_mutant_design,
        write_mutant_design,
    )
    from fpga_robotics.scenario.load import load_scenario

    scenario = load_scenario(
        "lost_target", ["sim.duration=2.0", 'camera.resolution="80x60"', "camera.noise_std=4"]
    )
    mutants = mutation.list_mutants(PARAMS, 40, seed=2)
    netlist, ports = write_mutant_design(PARAMS, mutants, tmp_path)
    assert re.search(rf"output \[{len(mutants) - 1}:0\] {WATCH_PORT};", Path(netlist).read_text())
    design = open_mutant_design(PARAMS, netlist, Path(ports).with_name(WATCH_PORTS_NAME))
    try:
        reference = ReferenceRun(scenario, design=design)
        seen = reference._loop.seen
        design.reset()
        expected = [_outputs(design.process_frame(rgb, color)) for rgb, color in seen]
        assert design.watch_risen() is not None
        never = differing = 0
        for m in mutants:
            design.set_runtime(mutation.MUTATION_SELECT, m.index)
            design.reset()
            first_difference = None
            for k, (rgb, color) in enumerate(seen):
                try:
                    out, filtered = _outputs(design.process_frame(rgb, color))
                except BackendError:  # no frame_done within the timeout: it differs
                    first_difference = k
                    break
                if out != expected[k][0] or not np.array_equal(filtered, expected[k][1]):
                    first_difference = k
                    break
            acted = reference.watch_first(m.index - 1)
            if acted is None:
                never += 1
                assert first_difference is None, m.describe()
            if first_difference is not None:
                differing += 1
                assert acted is not None and acted <= first_difference, m.describe()
        # The seed gives both kinds: the check above is not empty either way.
        assert never >= 2 and differing >= 5, (never, differing)
    finally:
        design.close()


@needs_mutation_toolchain
@pytest.mark.slow  # builds the mutants' Verilator model
def test_a_mutant_that_never_acts_is_given_the_reference_run_without_running(tmp_path):
    from fpga_robotics.loop.fork import ReferenceRun
    from fpga_robotics.loop.timings import run_scenario
    from fpga_robotics.mutation.design import (
        WATCH_PORTS_NAME,
        open_mutant_design,
        write_mutant_design,
    )
    from fpga_robotics.scenario.load import load_scenario

    scenario = load_scenario("follow_person", ["sim.duration=2.0", 'camera.resolution="80x60"'])
    mutants = mutation.list_mutants(PARAMS, 40, seed=2)
    netlist, ports = write_mutant_design(PARAMS, mutants, tmp_path)
    design = open_mutant_design(PARAMS, netlist, Path(ports).with_name(WATCH_PORTS_NAME))
    try:
        reference = ReferenceRun(scenario, design=design)
        quiet = [m for m in mutants if reference.watch_first(m.index - 1) is None]
        assert quiet, "seed 2 has mutants that never act in follow_person"
        for m in quiet[:3]:
            design.set_runtime(mutation.MUTATION_SELECT, m.index)
            forked = reference.run_variant(design, scenario, watch_bit=m.index - 1)
            assert design.frames_processed == 0  # reset, never run
            design.reset()
            assert_same_run(forked, run_scenario(scenario, backend=design))
    finally:
        design.close()
