"""Every formal check of ``fpga_robotics.hw.formal`` passes on the real design: the promises
of docs/formal.md are proved (prove), hold to the depth searched (bmc), or are reachable
(cover). Run with ``pytest -m formal``; they are ordinary tests in CI."""

import pytest

from fpga_robotics.flow.formal import run_check
from fpga_robotics.hw.formal import CHECKS

pytestmark = pytest.mark.formal


@pytest.mark.parametrize("check", CHECKS, ids=[c.name for c in CHECKS])
def test_check_passes(check, tmp_path):
    result = run_check(check, trace_dir=tmp_path)
    assert result.passed, f"{check.name}: {result.status} {result.detail} {result.trace}"
    assert result.depth == check.depth
