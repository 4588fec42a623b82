"""The physics benchmark: its command line (``fpga-robotics bench world``, or
``python -m fpga_robotics.bench world``) prints a line per world and reports bad arguments as
one line with exit status 2."""

import subprocess
import sys

import pytest

from fpga_robotics.bench.world import WORLDS, main


def test_prints_a_line_per_world(capsys):
    assert main(["--frames", "3", "--repeats", "1"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("8 steps of 4.17 ms per frame, 3 frames, median of 1 runs")
    assert [ln[2:34].strip() for ln in lines[1:-1]] == list(WORLDS)
    assert all(float(ln.split()[-10]) > 0 for ln in lines[1:-1])  # ms/frame
    assert all(float(ln.split()[-7].rstrip(")")) > 0 for ln in lines[1:-1])  # its CPU time
    # The cost of the terrain world's lookup and noise alone, after the worlds.
    assert lines[-1][2:34].strip() == "of which terrain and noise alone"
    assert float(lines[-1].split()[6]) > 0


@pytest.mark.parametrize(
    "args,message",
    [
        (
            ["--fps", "0"],
            "fpga-robotics bench world: error: --fps must be a number of hertz in (0, 240], got 0.0",
        ),
        (["--frames", "0"], "fpga-robotics bench world: error: --frames must be 1..1000000, got 0"),
        (
            ["--physics-hz", "nan"],
            "fpga-robotics bench world: error: --physics-hz must be a number of hertz in (0, 100000], got nan",
        ),
        (
            ["--fps", "300"],
            "fpga-robotics bench world: error: --fps must be a number of hertz in (0, 240], got 300.0",
        ),
    ],
)
def test_bad_arguments_are_one_line(args, message):
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.bench", "world", *args],
        capture_output=True,
        check=False,
        text=True,
    )
    assert (proc.returncode, proc.stdout) == (2, "")
    assert proc.stderr.splitlines() == [message]


@pytest.mark.parametrize(
    "what,args,message",
    [
        (
            "world",
            ["--repeats", "0"],
            "fpga-robotics bench world: error: --repeats must be 1..1000, got 0",
        ),
        (
            "camera",
            ["--sizes", "0x0"],
            "fpga-robotics bench camera: error: a size needs a width and height of 1..4096, got '0x0'",
        ),
    ],
)
def test_the_benchmarks_are_fpga_robotics_bench_subcommands(what, args, message, capsys):
    from fpga_robotics.cli import main as fpga_robotics

    with pytest.raises(SystemExit) as exc:
        fpga_robotics(["bench", what, *args])
    assert exc.value.code == 2
    assert capsys.readouterr().err.splitlines() == [message]
