"""A Verilog design that ends the run itself, in real-clock timing (docs/foreign.md): a call
of ``$finish``, ``$stop`` or ``$fatal`` stops the run with the file and line of the call and
its edge (never the process exiting, never the call ignored), the model runs again after a
reset; a result strobe that does not rise within ``result.timeout`` cycles after a frame is
the named timeout of compressed timing.

The designs are tests/data/design_stops/: ``stopper.v`` calls the task its ``which`` input
selects at edge 5500 (hand-counted: ``n`` counts edges from the reset, and the call is at the
edge that samples ``n == 5499``); ``late_result.v`` raises its strobe ``wait_cycles`` edges
after a frame's last pixel (``silent``: never).
"""

from pathlib import Path

import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main as run_main
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.foreign import ForeignDesign
from fpga_robotics.sim.backends.foreign_choice import verilator_only
from fpga_robotics.sim.pins import (
    DesignError,
    DesignStopped,
    PinError,
    VerilogPinSource,
    get_pin_backend,
    real_clock_timing,
)
from fpga_robotics.sim.pins.compiled import VerilatorPins

DATA = Path(__file__).parent / "data" / "design_stops"
STOPPER, STOPPER_PORTS = DATA / "stopper.v", DATA / "stopper_ports.toml"
LATE, LATE_PORTS = DATA / "late_result.v", DATA / "late_result_ports.toml"
#: The edge stopper.v calls its task at.
CALL_EDGE = 5500


def _line_of(text):
    """The line of stopper.v that holds ``text``."""
    lines = STOPPER.read_text().splitlines()
    return next(i for i, line in enumerate(lines, start=1) if text in line)


#: ``which`` -> how the error names the call (Verilator's hook cannot tell $stop from $fatal).
CALLS = {
    1: f"$finish at stopper.v:{_line_of('$finish;')}",
    2: f"$stop or $fatal at stopper.v:{_line_of('$stop;')}",
    3: f"$stop or $fatal at stopper.v:{_line_of('$fatal(')}",
}

#: No camera design, a bumper pin; 10 rows a second (camera.fps) at a 10 kHz clock: edge
#: 5500 is 0.55 s, during frame 5 (captured at 0.5 s).
STOPPER_SCENARIO = """
people = []
[sim]
duration = 1.0
clock_hz = 10000.0
[camera]
fps = 10.0
[robot]
model = "gopigo3"
[[robot.sensors]]
kind = "bumper"
"""

#: 40x30 frames at 10 fps on a 200 kHz clock (real_clock_timing spreads them over the period).
LATE_SCENARIO = f"""
people = []
[sim]
duration = 0.5
clock_hz = 200000.0
timing = "real_clock"
[camera]
resolution = "40x30"
fps = 10.0
[design]
verilog = "{LATE}"
ports = "{LATE_PORTS}"
"""


def _stopper_source():
    return VerilogPinSource(ForeignDesign([STOPPER], STOPPER_PORTS, pins=True))


def test_cxxrtl_is_refused_for_a_design_that_calls_them():
    # Yosys refuses $finish/$stop/$fatal outside an initial block: said before any build.
    with pytest.raises(PinError, match=r"^stopper: it calls \$stop, \$fatal or \$finish, .*"):
        get_pin_backend("cxxrtl", _stopper_source())


def test_a_call_named_in_a_comment_only_does_not_need_verilator(tmp_path):
    text = STOPPER.read_text()
    for call in ("$finish;", "$stop;", '$fatal(1, "stopper: fatal at n = %0d", n);'):
        text = text.replace(call, "/* no call */ ;")
    assert "$finish" in text  # still named, in the header comment
    (tmp_path / "stopper.v").write_text(text)
    design = ForeignDesign([tmp_path / "stopper.v"], STOPPER_PORTS, pins=True)
    assert verilator_only(design) is None
    assert verilator_only(_stopper_source().design).startswith("it calls $stop, $fatal")


@pytest.mark.slow
def test_each_call_stops_the_run_at_its_edge_and_the_model_runs_again(capfd):
    with get_pin_backend("auto", _stopper_source()) as pins:
        assert isinstance(pins, VerilatorPins)  # auto: the simulator that reports them
        for which, call in CALLS.items():
            pins.set_runtime("which", which)
            pins.reset()
            with pytest.raises(DesignStopped) as info:
                pins.run(3 * CALL_EDGE)
            assert (info.value.call, info.value.cycle) == (call, CALL_EDGE)
            assert str(info.value) == f"the design called {call} (edge {CALL_EDGE})"
            assert pins.cycle == CALL_EDGE and pins.peek("n") == CALL_EDGE
            with pytest.raises(DesignStopped, match=r"\(edge 5500\)$"):
                pins.run(10)  # a stopped model runs no further edge until the reset
            assert pins.cycle == CALL_EDGE
        pins.set_runtime("which", 0)
        pins.reset()
        assert pins.run(3 * CALL_EDGE).cycle == 3 * CALL_EDGE
        assert pins.peek("n") == 3 * CALL_EDGE
    out = capfd.readouterr().out
    # The calls were not Verilator's: no "Verilog $finish" notice, no abort. $fatal's own
    # message is the design's and is printed.
    assert "Verilog $" not in out and "Aborting" not in out
    assert "stopper: fatal at n = 5499" in out


def _run(argv, capsys):
    with pytest.raises(SystemExit) as info:
        run_cli(run_main, argv, prog="fpga-robotics run")
    return info.value.code, capsys.readouterr()


@pytest.mark.slow
def test_the_run_command_reports_the_call_in_one_line_and_runs_again(tmp_path, capsys):
    scenario = tmp_path / "stopper.toml"
    scenario.write_text(STOPPER_SCENARIO)
    base = ["--scenario", str(scenario), "--design", f"verilog:{STOPPER}"]
    base += ["--ports", str(STOPPER_PORTS), "--rerun", "off", "--quiet"]
    for which in (1, 3):
        code, captured = _run([*base, "--runtime", f"which={which}"], capsys)
        assert code == 2
        assert captured.err.splitlines() == [
            "fpga-robotics run: error: --design: stopper: frame 5: the design called "
            + f"{CALLS[which]} (edge {CALL_EDGE}, 0.55 s)"
        ]
        assert "verdict" not in captured.out  # no summary, as in compressed timing
    code, captured = _run([*base, "--runtime", "which=0"], capsys)
    assert code == 0, captured.err
    assert "verdict: PASS" in captured.out
    assert "design output count: last 10000" in captured.out  # 1 s at 10 kHz: every edge


@pytest.mark.slow
def test_a_shadow_design_that_calls_finish_is_named_not_the_primary(tmp_path, capsys):
    # The shadow is stopper.v held at which = 1 ($finish at edge 5500); the primary, the same
    # design at which = 0, never calls anything.
    scenario = tmp_path / "stopper.toml"
    scenario.write_text(STOPPER_SCENARIO)
    shadow_ports = tmp_path / "finishing_ports.toml"
    shadow_ports.write_text(STOPPER_PORTS.read_text().replace("which = 0", "which = 1"))
    argv = ["--scenario", str(scenario), "--design", f"verilog:{STOPPER}"]
    argv += ["--ports", str(STOPPER_PORTS), "--rerun", "off", "--quiet"]
    argv += ["--shadow", f"verilog:{STOPPER}", "--shadow-ports", str(shadow_ports)]
    code, captured = _run(argv, capsys)
    assert code == 2
    assert captured.err.splitlines() == [
        f"fpga-robotics run: error: --shadow: {STOPPER}: frame 5: the shadow design called "
        + f"{CALLS[1]} (edge {CALL_EDGE}, 0.55 s)"
    ]


def _late_run(pins, tmp_path, wait_cycles=0, silent=0):
    path = tmp_path / "late.toml"
    path.write_text(LATE_SCENARIO)
    pins.set_runtime("wait_cycles", wait_cycles)
    pins.set_runtime("silent", silent)
    return run_scenario(load_scenario(str(path)), backend=pins)


@pytest.mark.slow
def test_a_result_strobe_later_than_the_timeout_is_the_named_timeout(tmp_path):
    path = tmp_path / "late.toml"
    path.write_text(LATE_SCENARIO)
    scenario = load_scenario(str(path))
    source = VerilogPinSource(
        ForeignDesign([LATE], LATE_PORTS, scenario.params, pins=True), stream=True
    )
    # The frame's last pixel is at edge L; the strobe rises after edge L + wait_cycles and
    # frame_done (the map's latency 1 later) after L + wait_cycles + 1, the last edge the
    # timeout allows being L + 300 + 1: a wait of 300 is in time, 301 is not.
    last = real_clock_timing(40, 30, 10.0, 200000.0, 1).last_edge(40, 30)
    with get_pin_backend("auto", source) as pins:
        result = _late_run(pins, tmp_path, wait_cycles=300)
        assert result.summary["frames"] == 5
        for wait, silent in ((301, 0), (100, 1)):
            with pytest.raises(DesignError) as info:
                _late_run(pins, tmp_path, wait_cycles=wait, silent=silent)
            assert str(info.value) == (
                "late_result: frame 0: timeout: the result strobe 'done' never rose within "
                "300 cycles (result.timeout) after the frame"
            )
            assert pins.cycle == last + 300 + 1  # raised at the timeout's very edge


ASSERTER = """\
module asserter (input clk, input rst, input bump, output reg [15:0] n);
  always @(posedge clk) begin
    if (rst) n <= 16'd0; else n <= n + 16'd1;
    if (!rst) assert (n != 16'd50);
    if (!rst && n == 16'd20) $display("asserter: n is %0d", n);
  end
endmodule
"""
ASSERTER_MAP = """\
top = "asserter"
clock = { port = "clk" }
reset = { port = "rst" }
[connectors.bumper]
pressed = "bump"
[extra_outputs]
count = "n"
"""


@pytest.mark.slow
@pytest.mark.parametrize("simulator", ["cxxrtl", "verilator"])
def test_a_failing_assertion_is_not_checked_and_display_prints(simulator, tmp_path, capfd):
    # Verilator builds with --noassert; CXXRTL would abort the process on the $check cell
    # Yosys makes of it. Both run on, and print the design's $display (a $print cell).
    (tmp_path / "asserter.v").write_text(ASSERTER)
    (tmp_path / "asserter.toml").write_text(ASSERTER_MAP)
    design = ForeignDesign([tmp_path / "asserter.v"], tmp_path / "asserter.toml", pins=True)
    with get_pin_backend(simulator, VerilogPinSource(design)) as pins:
        assert pins.run(100).cycle == 100
        assert pins.peek("n") == 100
    assert capfd.readouterr().out.splitlines() == ["asserter: n is 20"]


FINISHER = """\
// A camera design: its strobe rises after each frame's last pixel; it calls $finish at
// the third frame's (frame 2's) last pixel.
module frame_finisher #(parameter integer PIXELS = 1200) (
  input clk, input rst, input px_valid, input [13:0] px_payload,
  output reg done, output signed [15:0] ml, output signed [15:0] mr
);
  reg [15:0] seen;
  reg [7:0] frames;
  wire [15:0] index = px_payload[12] ? 16'd0 : seen;
  always @(posedge clk) begin
    done <= 1'b0;
    if (rst) begin
      seen <= 16'd0; frames <= 8'd0;
    end else if (px_valid) begin
      seen <= index + 16'd1;
      if (index == PIXELS - 1) begin
        done <= 1'b1; frames <= frames + 8'd1;
        if (frames == 8'd2) $finish;
      end
    end
  end
  assign ml = 16'sd0;
  assign mr = 16'sd0;
endmodule
"""
FINISHER_MAP = """\
top = "frame_finisher"
clock = { port = "clk" }
reset = { port = "rst" }
pixels = { valid = "px_valid", payload = "px_payload" }
result = { strobe = "done", latency = 1 }
outputs = { motor_left = "ml", motor_right = "mr" }
"""
FINISHER_SCENARIO = """
people = []
[sim]
duration = 1.0
clock_hz = 200000.0
[camera]
resolution = "40x30"
fps = 10.0
"""


@pytest.mark.slow
def test_a_call_ends_a_run_alike_in_both_timings(tmp_path, capsys):
    # Frame 2's call, in either timing: the same error (real-clock adds the edge), no
    # summary, and the recording closed with the frames before it.
    (tmp_path / "frame_finisher.v").write_text(FINISHER)
    (tmp_path / "finisher.toml").write_text(FINISHER_MAP)
    (tmp_path / "scenario.toml").write_text(FINISHER_SCENARIO)
    line = FINISHER.splitlines().index("        if (frames == 8'd2) $finish;") + 1
    error = (
        "fpga-robotics run: error: --design: frame_finisher: frame 2: the design called "
        f"$finish at frame_finisher.v:{line}"
    )
    # Frame 2 is captured at edge 40000 (0.2 s at 200 kHz); its pixels from the next edge.
    edge = real_clock_timing(40, 30, 10.0, 200000.0, 40001).last_edge(40, 30)
    suffix = {"compressed": "", "real_clock": f" (edge {edge}, {edge / 200000.0:.6g} s)"}
    for timing in ("compressed", "real_clock"):
        recording = tmp_path / f"{timing}.rrd"
        code, captured = _run(
            [
                *("--scenario", str(tmp_path / "scenario.toml")),
                *("--design", f"verilog:{tmp_path / 'frame_finisher.v'}"),
                *("--ports", str(tmp_path / "finisher.toml")),
                *("--set", f'sim.timing="{timing}"'),
                *("--rerun", f"save:{recording}", "--quiet"),
            ],
            capsys,
        )
        assert code == 2
        lines = captured.err.splitlines()
        assert lines[-1] == error + suffix[timing]
        assert any(x.startswith(f"saved 2 frames (2 with images) to {recording}") for x in lines)
        assert recording.is_file()
        assert "verdict" not in captured.out
