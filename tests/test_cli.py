"""The ``fpga-robotics`` command: every subcommand reaches its module and names itself."""

import subprocess
import sys

import pytest

from fpga_robotics import cli


@pytest.mark.parametrize("argv, prog", [
    (["run", "--help"], "fpga-robotics run"),
    (["export", "--help"], "fpga-robotics export"),
    (["board", "--help"], "fpga-robotics board"),
    (["bench", "--help"], "fpga-robotics bench design"),
    (["bench", "design", "--help"], "fpga-robotics bench design"),
    (["bench", "pysim", "--help"], "fpga-robotics bench pysim"),
    (["bench", "camera", "--help"], "fpga-robotics bench camera"),
    (["bench", "world", "--help"], "fpga-robotics bench world"),
    (["bench", "viewer", "--help"], "fpga-robotics bench viewer"),
    (["bench", "shadow", "--help"], "fpga-robotics bench shadow"),
])
def test_each_subcommand_shows_its_own_help(argv, prog, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    assert info.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: {prog}")


def test_top_level_help_lists_every_command(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["--help"])
    assert info.value.code == 0
    out = capsys.readouterr().out
    for name in cli.COMMANDS:
        assert f"  {name} " in out


def test_bench_list_names_every_benchmark(capsys):
    with pytest.raises(SystemExit):
        cli.main(["bench", "--list"])
    out = capsys.readouterr().out
    assert all(f"  {name} " in out for name in cli.BENCHMARKS)


def test_console_script_and_module_alias_run_the_same_command(tmp_path):
    # `python -m fpga_robotics` is the console script; `python -m fpga_robotics.export` the
    # documented alias: both write the same Verilog.
    a, b = tmp_path / "a.v", tmp_path / "b.v"
    for argv in ([sys.executable, "-m", "fpga_robotics", "export", "-o", str(a)],
                 [sys.executable, "-m", "fpga_robotics.export", "-o", str(b)]):
        subprocess.run(argv, check=True, capture_output=True, timeout=300)
    assert a.read_text() == b.read_text() and "module follow_target" in a.read_text()
