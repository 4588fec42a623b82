"""Test-wide settings.

Property tests draw the same examples on every run (a seed fixes every random choice), so a
CI result never depends on luck; set HYPOTHESIS_PROFILE=explore to draw fresh examples
locally.

The fast tier (``python -m pytest -m "not slow"``) builds no Verilator model and runs no
place and route: a test not marked ``slow`` that reaches one of those builds fails, naming
itself and the build (tests/fast_tier/slow_builds.py), in its own process and in the Python
processes it starts.
"""

import os
import sys
from pathlib import Path

import pytest
from hypothesis import settings

FAST_TIER_DIR = Path(__file__).resolve().parent / "fast_tier"
sys.path.insert(0, str(FAST_TIER_DIR))

import slow_builds  # found through the line above

settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore")
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


@pytest.fixture(autouse=True)
def _fast_tier_builds_nothing_slow(request, monkeypatch):
    if request.node.get_closest_marker("slow") is not None:
        return
    test = request.node.nodeid
    slow_builds.forbid(monkeypatch, test)
    # The same check in the Python processes the test starts (tests/fast_tier/sitecustomize.py).
    monkeypatch.setenv("FPGA_ROBOTICS_FAST_TIER", test)
    path = os.environ.get("PYTHONPATH")
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(FAST_TIER_DIR), path])))


def pytest_collection_modifyitems(items):
    """The formal proofs run SymbiYosys for minutes: slow-tier too, not the edit-test loop."""
    for item in items:
        if item.get_closest_marker("formal") and not item.get_closest_marker("slow"):
            item.add_marker(pytest.mark.slow)
