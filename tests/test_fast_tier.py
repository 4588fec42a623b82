"""The fast tier's check (tests/conftest.py, tests/fast_tier/): a test not marked slow that
reaches a Verilator build or place and route fails, naming itself; a slow test is let through."""

import subprocess
import sys

import pytest
import slow_builds

from fpga_robotics.flow import board
from fpga_robotics.sim.backends import foreign, verilator
from fpga_robotics.sim.pins.compiled import VerilatorPins


@pytest.mark.parametrize("build", [
    lambda: verilator.verilator_build_plan(None, "frame"),
    lambda: foreign.foreign_build_plan(None),
    lambda: VerilatorPins.plan(None),
    lambda: board.build_bitstream("ulx3s-85f", "unused"),
])
def test_a_fast_test_cannot_build(build, request):
    with pytest.raises(slow_builds.SlowBuildInFastTier) as info:
        build()
    message = str(info.value)
    assert request.node.nodeid in message and "mark the test @pytest.mark.slow" in message


def test_a_python_process_of_a_fast_test_cannot_build(tmp_path):
    code = ("from fpga_robotics.sim.backends.verilator import VerilatorBackend\n"
            "VerilatorBackend.build_plan(None, 'frame')\n")
    proc = subprocess.run([sys.executable, "-c", code], check=False, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode != 0
    assert "test_a_python_process_of_a_fast_test_cannot_build builds a Verilator model" in (
        proc.stderr)


@pytest.mark.slow
def test_a_slow_test_reaches_the_real_entry_points():
    for name, entries in slow_builds.ENTRY_POINTS.items():
        for path, _ in entries:
            owner = sys.modules[name]
            for part in path.split("."):
                owner = getattr(owner, part)
            assert owner.__qualname__.rpartition(".")[2] != "refuse", (name, path)
