"""The ULX3S board top: it elaborates and converts to Verilog, its LPF puts every signal on the
published pin, the PLL and switch logic are right, the CLI handles bad input, and (slow) the
whole open flow (Yosys, nextpnr-ecp5, ecppack via YoWASP) meets timing."""

import json
import re
import subprocess
import sys

import pytest
from amaranth.sim import Simulator

from fpga_robotics.cli.board import main
from fpga_robotics.flow.board import (
    BuildReport,
    ClockTiming,
    export_board,
    parse_nextpnr_report,
)
from fpga_robotics.hw.board.clocking import ecp5_pll_params
from fpga_robotics.hw.board.color_select import SwitchColorSelect
from fpga_robotics.hw.errors import UserError
from fpga_robotics.hw.pixel import TargetColor

# The published pin assignment (ulx3s_v20.lpf of the published robot), transcribed here
# independently of hw/board/pins.py.
PUBLISHED_SITES = {
    **{
        f"ov7670_0__data__io[{i}]": s
        for i, s in enumerate(["B11", "C11", "A10", "A11", "A9", "B10", "B9", "C10"])
    },
    "ov7670_0__xclk__io": "A7",
    "ov7670_0__pclk__io": "A8",
    "ov7670_0__href__io": "C8",
    "ov7670_0__vsync__io": "B8",
    "ov7670_0__siod__io": "H4",
    "ov7670_0__sioc__io": "G5",
    "ov7670_0__reset__io": "C18",
    "gopigo3_spi_0__cs__io": "C6",
    "gopigo3_spi_0__clk__io": "C7",
    "gopigo3_spi_0__cipo__io": "D18",
    "gopigo3_spi_0__copi__io": "E17",
    "button_fire_0__io": "R1",
    "clk25_0__io": "G2",
    **{f"led_{i}__io": s for i, s in enumerate(["B2", "C2", "C1", "D2", "D1", "E2", "E1", "H3"])},
}


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("ulx3s")
    export_board("ulx3s-85f", str(out))
    return out


def test_export_writes_verilog_with_unchanged_follow_target(exported):
    text = (exported / "ulx3s_follow_target.v").read_text()
    assert re.search(r"^module ulx3s_follow_target\(", text, re.MULTILINE)
    assert "EHXPLLL" in text
    # FollowTarget is inside, as its own module with its filter, tracker and motor blocks.
    for sub in (
        "core.design ",
        "core.design.color_filter ",
        "core.design.tracker ",
        "core.design.motor ",
    ):
        assert f"module \\ulx3s_follow_target.{sub}" in text


def test_lpf_matches_published_pins(exported):
    lpf = (exported / "ulx3s_follow_target.lpf").read_text()
    sites = dict(re.findall(r'LOCATE COMP "([^"]+)" SITE "([^"]+)";', lpf))
    for port, site in PUBLISHED_SITES.items():
        assert sites.get(port) == site, f"{port} should be on {site}, LPF says {sites.get(port)}"
    assert 'FREQUENCY NET "clocking.pll.clk_out" 50000000.0 HZ;' in lpf
    assert 'FREQUENCY PORT "ov7670_0__pclk__io" 12500000.0 HZ;' in lpf
    # Every ULX3S I/O is 3.3 V.
    assert lpf.count("IO_TYPE=LVCMOS33") == len(sites)


def test_pll_divider_search():
    p = ecp5_pll_params(25e6, 50e6)
    assert p.out_freq == 50e6 and 400e6 <= p.vco_freq <= 800e6
    assert p.in_freq / p.clki_div * p.clkfb_div == 50e6
    assert p.clkop_cphase == (p.clkop_div - 1) // 2
    with pytest.raises(ValueError, match="outside"):
        ecp5_pll_params(25e6, 1e9)


@pytest.mark.parametrize(
    "switches,colour",
    [
        (0b000, "red"),
        (0b001, "red"),
        (0b010, "green"),
        (0b100, "blue"),
        (0b011, "yellow"),
        (0b101, "magenta"),
        (0b110, "cyan"),
        (0b111, "white"),
    ],
)
def test_switches_select_colour(switches, colour):
    dut = SwitchColorSelect()
    sim = Simulator(dut)
    sim.add_clock(1e-6)
    seen = []

    async def bench(ctx):
        ctx.set(dut.switches, switches)
        for _ in range(3):  # through the two-flop synchroniser; bounded
            await ctx.tick()
        seen.append(ctx.get(dut.color_sel))

    sim.add_testbench(bench)
    sim.run()
    assert seen == [TargetColor[colour.upper()]]


def test_unknown_board_lists_supported_ones():
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics", "board", "--board", "nope"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert "ulx3s-85f" in proc.stderr and "unknown board 'nope'" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_board_rejects_other_geometries(tmp_path):
    with pytest.raises(UserError, match="160x120"):
        main(["--board", "ulx3s-85f", "-o", str(tmp_path), "--width", "320", "--height", "240"])
    assert list(tmp_path.iterdir()) == []


def test_report_parsing_and_timing_verdict():
    report = parse_nextpnr_report(
        {
            "utilization": {"TRELLIS_COMB": {"used": 10, "available": 100}},
            "fmax": {
                "a": {"achieved": 49.9, "constraint": 50},
                "b": {"achieved": 80, "constraint": 12.5},
            },
        }
    )
    assert report.resource("TRELLIS_COMB") == (10, 100)
    assert [c.ok for c in report.clocks] == [False, True]
    assert not report.timing_ok
    assert not BuildReport().timing_ok  # no constrained clock is not a pass
    assert BuildReport(clocks=[ClockTiming("x", 50.0, 50.0)]).timing_ok


def test_export_cli_board_option(tmp_path):
    from fpga_robotics.cli.export import main as export_main

    assert export_main(["--board", "ulx3s-85f", "-o", str(tmp_path)]) == 0
    assert (tmp_path / "ulx3s_follow_target.v").stat().st_size > 10_000
    assert "LOCATE COMP" in (tmp_path / "ulx3s_follow_target.lpf").read_text()
    with pytest.raises(UserError, match="supported boards: ulx3s-85f"):
        export_main(["--board", "ulx3s-12f", "-o", str(tmp_path / "x")])
    with pytest.raises(UserError, match="--bitstream needs --board"):
        export_main(["--bitstream"])


@pytest.mark.slow
def test_bitstream_build_meets_timing(tmp_path):
    """The full open flow on the real board top, through the documented command (about
    2-3 minutes on 2 cores); nothing is cached, the build directory is fresh."""
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "fpga_robotics.export",
            "--board",
            "ulx3s-85f",
            "-o",
            str(tmp_path),
            "--bitstream",
            "--seed",
            "1",
        ],
        capture_output=True,
        text=True,
        timeout=1200,
        check=False,
    )
    print(proc.stdout, proc.stderr)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "PASS" in proc.stdout and "FAIL" not in proc.stdout
    report = parse_nextpnr_report(
        json.loads((tmp_path / "ulx3s_follow_target.report.json").read_text())
    )
    assert report.timing_ok, report.format()
    assert sorted(c.required_mhz for c in report.clocks) == [12.5, 50.0]
    assert report.resource("TRELLIS_COMB")[0] > 500
    assert report.resource("TRELLIS_FF")[0] > 200
    assert report.resource("EHXPLLL")[0] == 1
    assert (tmp_path / "ulx3s_follow_target.bit").stat().st_size > 10_000
