"""``fpga-robotics board --design REF``: a design of one's own on the robot's ULX3S. Its
wheels go to the GoPiGo3, its camera stream to the OV7670, its connector pins to free header
pins (the LPF puts them on the sites of ``HEADER_SITES``); a port the board cannot serve is
one line, exit 2, and nothing is written."""

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from fpga_robotics import cli
from fpga_robotics.flow.board import parse_nextpnr_report

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
