"""Test-wide settings.

Property tests draw the same examples on every run (a seed fixes every random choice), so a
CI result never depends on luck; set HYPOTHESIS_PROFILE=explore to draw fresh examples
locally.

The fast tier (``python -m pytest -m "not slow"``) builds no Verilator model and runs no
place and route: a test not marked ``slow`` that reaches one of those builds fails, naming
itself and the build (tests/fast_tier/slow_builds.py), in its own process and in the Python
processes it starts. The documentation's end-to-end blocks and the tests named in
tests/fast_tier/heavy_tests.txt are slow-tier too, so that the fast tier stays an edit-test loop
of a few minutes.
"""

import os
import signal
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


@pytest.fixture(autouse=True)
def _interrupts_as_found():
    """Each test leaves Ctrl-C and SIGTERM as it found them, handlers and signal mask alike:
    a process a later test starts inherits an ignored or blocked signal (the Ctrl-C tests
    then never see their run stop), so one test's leftover must not reach another's."""
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    yield
    changed = [s.name for s, h in handlers.items() if signal.getsignal(s) is not h]
    if signal.pthread_sigmask(signal.SIG_SETMASK, mask) != mask:
        changed.append("mask")
    for s, h in handlers.items():
        signal.signal(s, h)
    if changed:  # said, for whoever reads the log; the next test starts clean either way
        print(f"signal handling left changed ({', '.join(changed)}): restored", file=sys.stderr)


#: The documentation's own command and Python blocks run end to end (closed-loop runs,
#: campaigns, exports): the full suite runs them, the edit-test loop does not.
DOCS_RUNS = ("test_documented_commands", "test_documented_python")


def heavy_tests():
    """The node ids of tests/fast_tier/heavy_tests.txt (a comment after ``#`` gives the cost)."""
    lines = (FAST_TIER_DIR / "heavy_tests.txt").read_text().splitlines()
    return [line.split("#")[0].strip() for line in lines if line.split("#")[0].strip()]


def is_heavy(nodeid, heavy):
    """A line names a test, every parametrization of a test (no brackets), or a whole file."""
    return any(
        nodeid == h
        or (nodeid.startswith(h + "[") and "[" not in h)
        or ("::" not in h and nodeid.startswith(h + "::"))
        for h in heavy
    )


def pytest_collection_modifyitems(items):
    """Slow-tier too, not the edit-test loop: the formal proofs (SymbiYosys runs minutes), the
    documentation's end-to-end blocks and the tests listed as heavy."""
    heavy = heavy_tests()
    for item in items:
        if item.get_closest_marker("slow"):
            continue
        if (
            item.get_closest_marker("formal")
            or item.originalname in DOCS_RUNS
            or is_heavy(item.nodeid, heavy)
        ):
            item.add_marker(pytest.mark.slow)
