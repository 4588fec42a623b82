"""The fast tier's check (tests/conftest.py, tests/fast_tier/): a test not marked slow that
reaches a Verilator model or place and route fails, naming itself; other builds, and a slow
test, are let through."""

import subprocess
import sys

import pytest
import slow_builds

from fpga_robotics.flow import board
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import build_cache, get_backend

SMALL = FollowTargetParams(width=40, height=16)


def _write(name):
    def build(directory):
        (directory / name).write_text("built")

    return build


@pytest.mark.parametrize(
    "build",
    [
        lambda: get_backend("verilator", SMALL),
        lambda: build_cache.get_or_build("pins-verilator-x", "k" * 64, ["a"], _write("a")),
        lambda: board.build_bitstream("ulx3s-85f", "unused"),
    ],
)
def test_a_fast_test_cannot_build(build, request):
    with pytest.raises(slow_builds.SlowBuildInFastTier) as info:
        build()
    message = str(info.value)
    assert request.node.nodeid in message and "mark the test @pytest.mark.slow" in message


def test_other_builds_go_through(tmp_path):
    entry = build_cache.get_or_build(
        "cxxrtl-x", "c" * 64, ["lib.so"], _write("lib.so"), root=tmp_path
    )
    assert entry.built and (entry.path / "lib.so").read_text() == "built"


def test_a_python_process_of_a_fast_test_cannot_build(tmp_path):
    code = (
        "from fpga_robotics.sim.backends import build_cache\n"
        "build_cache.get_or_build('verilator-x', 'k' * 64, ['a'], None)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        check=False,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode != 0
    assert "test_a_python_process_of_a_fast_test_cannot_build builds a Verilator model" in (
        proc.stderr
    )


@pytest.mark.slow
def test_a_slow_test_reaches_the_real_entry_points():
    for name, entries in slow_builds.ENTRY_POINTS.items():
        for attr, _, _ in entries:
            assert not hasattr(getattr(sys.modules[name], attr), "guarded"), (name, attr)


def test_every_heavy_test_named_exists():
    """A renamed or removed test must leave tests/fast_tier/heavy_tests.txt too, or the list
    would silently stop marking anything."""
    from conftest import heavy_tests, is_heavy

    listed = heavy_tests()
    assert listed, "heavy_tests.txt names no test"
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"]
        + sorted({h.split("::")[0] for h in listed}),
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
    )
    collected = [line.strip() for line in result.stdout.splitlines() if "::" in line]
    missing = [h for h in listed if not any(is_heavy(c, [h]) for c in collected)]
    assert not missing, f"heavy_tests.txt names tests that do not exist: {missing}"


def test_heavy_and_docs_tests_are_slow_tier():
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "--collect-only",
            "-q",
            "-m",
            "not slow",
            "-p",
            "no:cacheprovider",
            "tests/test_real_clock.py",
            "tests/test_docs_commands.py",
        ],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
    )
    fast = result.stdout.splitlines()
    assert any("test_real_clock.py::" in t for t in fast), result.stdout[-2000:]
    assert not any("test_the_ultrasound_variant_drives_into_the_box" in t for t in fast)
    assert not any("test_documented_commands[" in t for t in fast)
