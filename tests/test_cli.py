"""The ``fpga-robotics`` command: every subcommand reaches its module, names itself, answers
``--help`` with its defaults, and reports a bad argument as one line with exit code 2."""

import subprocess
import sys
from importlib.metadata import version

import pytest

from fpga_robotics import cli


@pytest.mark.parametrize(
    "argv, prog",
    [
        (["run", "--help"], "fpga-robotics run"),
        (["export", "--help"], "fpga-robotics export"),
        (["board", "--help"], "fpga-robotics board"),
        (["bench", "--help"], "fpga-robotics bench [WHAT]"),
        (["bench", "design", "--help"], "fpga-robotics bench design"),
        (["bench", "pysim", "--help"], "fpga-robotics bench pysim"),
        (["bench", "camera", "--help"], "fpga-robotics bench camera"),
        (["bench", "world", "--help"], "fpga-robotics bench world"),
        (["bench", "viewer", "--help"], "fpga-robotics bench viewer"),
        (["bench", "shadow", "--help"], "fpga-robotics bench shadow"),
        *[([name, "--help"], f"fpga-robotics {name}") for name in cli.COMMANDS if name != "bench"],
    ],
)
def test_each_subcommand_shows_its_own_help(argv, prog, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    assert info.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: {prog}")


@pytest.mark.parametrize(
    "argv, says",
    [
        # run and sweep run any design, not only FollowTarget or a Verilog one.
        (["run", "--help"], "Run a design (the scenario's, FollowTarget by default, or --design"),
        (["sweep", "--help"], "--design REF "),
    ],
)
def test_the_design_options_are_told_as_they_are(argv, says, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = " ".join(capsys.readouterr().out.split())
    assert info.value.code == 0 and says in out


def test_top_level_help_lists_every_command(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for name in cli.COMMANDS:
        assert f"  {name} " in out


@pytest.mark.parametrize("flag", ["--list", "--help", "-h"])
def test_bench_list_names_every_benchmark(flag, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["bench", flag])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: fpga-robotics bench [WHAT]")
    assert all(f"  {name} " in out for name in cli.BENCHMARKS)


def test_a_benchmarks_help_has_no_markup(capsys):
    with pytest.raises(SystemExit):
        cli.main(["bench", "camera", "--help"])
    out = capsys.readouterr().out
    assert "usage: fpga-robotics bench camera" in out and "``" not in out


def test_console_script_and_module_alias_run_the_same_command(tmp_path):
    # `python -m fpga_robotics` is the console script; `python -m fpga_robotics.export` the
    # documented alias: both write the same Verilog.
    a, b = tmp_path / "a.v", tmp_path / "b.v"
    for argv in (
        [sys.executable, "-m", "fpga_robotics", "export", "-o", str(a)],
        [sys.executable, "-m", "fpga_robotics.export", "-o", str(b)],
    ):
        subprocess.run(argv, check=True, capture_output=True, timeout=300)
    assert a.read_text() == b.read_text() and "module follow_target" in a.read_text()


def test_version_is_the_installed_package_version(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out == f"fpga-robotics {version('fpga-robotics')}\n"


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "--target-color", "purple"],
        ["run", "--backend", "iverilog"],
        ["run", "--no-such-option"],
        ["export", "--top", "nope"],
        ["ports"],
        ["readback"],
        ["readback", "a.rrd", "b.rrd"],
        ["sweep", "report"],
        ["formal", "--depth", "deep"],
        ["mutate", "--mutants", "many"],
        ["board", "--seed", "x"],
        ["new"],
        ["new", "a", "b"],
        ["designs", "--no-such-option"],
        *[[name, "--no-such-option"] for name in cli.COMMANDS if name != "bench"],
        ["bench", "design", "--no-such-option"],
    ],
)
def test_a_bad_argument_is_one_line_naming_the_command(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert err.count("\n") == 1, err
    assert err.startswith(f"fpga-robotics {' '.join(argv[:1])}"), err
    assert "error:" in err


def test_a_missing_argument_is_named_as_the_usage_names_it(capsys):
    with pytest.raises(SystemExit):
        cli.main(["ports"])
    assert capsys.readouterr().err == (
        "fpga-robotics ports: error: the following arguments are required: PORTS.toml\n"
    )


def test_run_help_shows_the_default_scenario_values(capsys):
    # follow_person.toml: resolution 160x120, 30 s, red; the run's own defaults as given.
    with pytest.raises(SystemExit):
        cli.main(["run", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "camera and design resolution (default: the scenario's; follow_person: 160x120)" in out
    assert "simulated seconds (default: the scenario's; follow_person: 30.0)" in out
    assert "initial colour select (default: the scenario's; follow_person: red)" in out
    assert (
        "--scenario NAME|PATH a shipped scenario (see --list-scenarios) or a .toml file "
        "(default: follow_person)" in out
    )
    assert "--log-every N log every Nth frame's images to the viewer (default: 1)" in out


def test_board_defaults_to_its_only_board(tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["board", "-o", str(tmp_path)])
    assert info.value.code == 0
    assert "LOCATE COMP" in (tmp_path / "ulx3s_follow_target.lpf").read_text()
    assert "for board ulx3s-85f" in capsys.readouterr().out


def test_sweep_usage_shows_the_report_form(capsys):
    with pytest.raises(SystemExit):
        cli.main(["sweep", "--help"])
    usage = capsys.readouterr().out.split("\n\n")[0]
    assert "fpga-robotics sweep report DIR" in usage


@pytest.mark.parametrize(
    "module, command",
    [
        ("fpga_robotics.run", "run"),
        ("fpga_robotics.export", "export"),
        ("fpga_robotics.formal", "formal"),
        ("fpga_robotics.sweep", "sweep"),
        ("fpga_robotics.mutation", "mutate"),
        # Each command's own module (they ran nothing and exited 0).
        *((f"fpga_robotics.cli.{c}", c) for c in cli.COMMANDS if c != "bench"),
    ],
)
def test_module_aliases_name_themselves_as_the_command(module, command):
    proc = subprocess.run(
        [sys.executable, "-m", module, "--no-such-option"],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"fpga-robotics {command}: error: "), proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
