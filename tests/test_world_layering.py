"""The simulation library never imports the application: the world, the camera and their
benchmarks load without ``fpga_robotics.errors``, ``scenario``, ``run``... (their command
lines live in the application layer, ``fpga_robotics.camera_bench`` and ``world_bench``)."""

import subprocess
import sys

import pytest

#: The library packages; every other ``fpga_robotics.X`` module is the application.
LIBRARY = ("fpga_robotics.hw", "fpga_robotics.sim", "fpga_robotics.viz")

SIM_MODULES = (
    "fpga_robotics.sim.world",
    "fpga_robotics.sim.world.bench",
    "fpga_robotics.sim.world.config",
    "fpga_robotics.sim.world.motors",
    "fpga_robotics.sim.world.people",
    "fpga_robotics.sim.world.world",
    "fpga_robotics.sim.camera",
    "fpga_robotics.sim.camera_bench",
    "fpga_robotics.sim.scene",
)


def loaded_application_modules(module):
    code = (
        f"import sys, importlib; importlib.import_module({module!r}); "
        "print('\\n'.join(m for m in sys.modules if m.startswith('fpga_robotics.')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    return [m for m in out if not m.startswith(tuple(p + "." for p in LIBRARY))
            and m not in LIBRARY]


@pytest.mark.parametrize("module", SIM_MODULES)
def test_sim_modules_import_no_application_module(module):
    assert loaded_application_modules(module) == []


@pytest.mark.parametrize("module,args,message", [
    ("fpga_robotics.sim.camera_bench", ["--sizes", "160by120"],
     "camera_bench: error: a size is WIDTHxHEIGHT, e.g. 160x120; got '160by120'"),
    ("fpga_robotics.camera_bench", ["--frames", "0"],
     "camera_bench: error: --frames must be 1..100000 and --repeats 1..1000, got 0 and 5"),
    ("fpga_robotics.sim.world.bench", ["--fps", "0"],
     "world_bench: error: --fps must be a number of hertz in (0, 200], got 0.0"),
    ("fpga_robotics.world_bench", ["--frames", "0"],
     "world_bench: error: --frames must be 1..1000000, got 0"),
    ("fpga_robotics.world_bench", ["--physics-hz", "nan"],
     "world_bench: error: --physics-hz must be a number of hertz in (0, 100000], got nan"),
])
def test_bench_command_lines_report_bad_arguments_in_one_line(module, args, message):
    proc = subprocess.run([sys.executable, "-m", module, *args], capture_output=True, check=False,
                          text=True)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [message]
    assert proc.stdout == ""


def test_world_bench_prints_a_line_per_world(capsys):
    from fpga_robotics.sim.world.bench import WORLDS
    from fpga_robotics.world_bench import main

    assert main(["--frames", "3", "--repeats", "1"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("7 steps of 5.00 ms per frame, 3 frames")
    assert [ln.split("  ")[1].strip() for ln in lines[1:]] == [
        name for name in WORLDS]
