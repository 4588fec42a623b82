"""``sim.clock_hz``: the default, a clock the run would not read (a warning, which
``--strict`` refuses), and the design tables that count time on the run's clock."""

from pathlib import Path

import pytest

from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main
from fpga_robotics.scenario.load import ScenarioError, load_scenario

USER_DESIGNS = Path(__file__).parent / "data" / "user_designs"
UNREAD = "changes nothing: the design runs in compressed timing"


def _clock_warnings(scenario):
    return [w for w in scenario.warnings if w.startswith("sim.clock_hz")]


def test_an_unset_clock_is_50_mhz_and_left_out_of_the_data():
    s = load_scenario("obstacle_between")
    assert s.sim.timing == "real_clock" and s.sim.clock_hz == 50e6
    assert "clock_hz" not in s.data["sim"]
    assert _clock_warnings(load_scenario("follow_person")) == []  # nothing given


@pytest.mark.parametrize(
    "scenario,items",
    [
        ("follow_person", ["sim.clock_hz=1e6"]),
        ("turret", ["sim.clock_hz=2e6"]),
        # The default value written out is still a value that changes nothing.
        ("follow_person", ["sim.clock_hz=5e7"]),
    ],
)
def test_a_clock_in_compressed_timing_is_a_warning(scenario, items):
    s = load_scenario(scenario, items)
    assert s.sim.timing == "compressed"
    expected = (
        f"sim.clock_hz {s.sim.clock_hz:g} {UNREAD}, clocked only while the pixels flow, at no "
        'clock rate; set sim.timing = "real_clock" to run it on that clock, or leave '
        "sim.clock_hz out"
    )
    assert _clock_warnings(s) == [expected]


def test_a_clock_the_run_reads_is_no_warning():
    real = load_scenario("follow_person", ["sim.clock_hz=1e6", 'sim.timing="real_clock"'])
    assert real.sim.clock_hz == 1e6 and _clock_warnings(real) == []
    assert _clock_warnings(load_scenario("obstacle_between", ["sim.clock_hz=1e6"])) == []
    # A camera-only design of one's own in compressed timing: its frame's budget of edges.
    own = load_scenario(str(USER_DESIGNS / "red_frames.toml"))
    assert own.sim.timing == "compressed" and own.sim.clock_hz == 200000.0
    assert _clock_warnings(own) == []


def test_run_prints_it_and_strict_refuses_it(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text("[sim]\nduration = 0.2\nclock_hz = 2e6\n")
    argv = ["--scenario", str(path), "--rerun", "off", "--backend", "model", "--quiet"]
    with pytest.raises(SystemExit) as info:
        run_cli(main, [*argv, "--strict"], prog="fpga-robotics run")
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert err.count("\n") == 1 and f"sim.clock_hz 2e+06 {UNREAD}" in err
    with pytest.raises(SystemExit) as info:
        run_cli(main, argv, prog="fpga-robotics run")
    err = capsys.readouterr().err
    assert f"warning: scenario 's': sim.clock_hz 2e+06 {UNREAD}" in err


# A design's tables that count time on the run's clock ----------------------------------------


def test_the_ultrasound_driver_counts_on_the_runs_clock():
    # obstacle_between at 2 MHz: the driver's clock_hz left out is the run's, so an echo of
    # the HC-SR04's width for 1.5 m (2 d / 343 m/s at 2 MHz: 17,493 edges) reads 1500 mm.
    # Before, the driver kept its 50 MHz default and read the same echo as 60 mm.
    s = load_scenario("obstacle_between", ["sim.clock_hz=2e6"])
    us = s.design_tables["ultrasound"]
    assert us.clock_hz == 2_000_000
    edges = round(2 * 1.5 / 343.0 * 2e6)
    assert us.distance_of(edges) == pytest.approx(1500, abs=1)
    default = load_scenario("obstacle_between")
    assert default.design_tables["ultrasound"].clock_hz == 50_000_000


@pytest.mark.parametrize(
    "items,message",
    [
        (
            ["sim.clock_hz=2e6", "design.ultrasound.clock_hz=50000000"],
            (
                "design.ultrasound.clock_hz 50000000 does not match sim.clock_hz 2000000; "
                "leave design.ultrasound.clock_hz out to take it"
            ),
        ),
        (
            ["sim.clock_hz=20000", "camera.fps=1", 'camera.resolution="16x4"', "design.margin_x=0"],
            (
                "design.ultrasound: clock_hz=20000 is too slow for trigger_us=12 and "
                "wait_us=10000: they must last at least 1 and 2 cycles (clock_hz is sim.clock_hz)"
            ),
        ),
    ],
)
def test_an_ultrasound_clock_against_the_runs_is_refused(items, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario("obstacle_between", items)
    assert str(info.value) == message


def test_an_ultrasound_clock_that_matches_the_runs_is_kept():
    s = load_scenario("obstacle_between", ["sim.clock_hz=2e5", "design.ultrasound.clock_hz=200000"])
    assert s.design_tables["ultrasound"].clock_hz == 200_000
