"""``fpga-robotics mutate`` of ``tests/data/bump_stop.v`` in this process, for the tests of
the robot judge on a Verilog design of one's own."""

from pathlib import Path

import pytest

from fpga_robotics import cli

DATA = Path(__file__).parent / "data"


def mutate_bump_stop(out, capsys, *more):
    """``mutate --design verilog:bump_stop.v`` (2,000 unit cycles, quiet) into ``out`` with the
    options ``more``; returns ``(exit code, stdout, stderr)``."""
    argv = ["mutate", "--design", f"verilog:{DATA / 'bump_stop.v'}"]
    argv += ["--ports", str(DATA / "bump_stop_ports.toml"), "--cycles", "2000"]
    with pytest.raises(SystemExit) as info:
        cli.main([*argv, "--out", str(out), "--quiet", *more])
    captured = capsys.readouterr()
    return info.value.code, captured.out, captured.err
