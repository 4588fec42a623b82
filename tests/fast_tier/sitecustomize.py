"""Python processes started by a fast-tier test (tests/conftest.py puts this folder on
PYTHONPATH and names the test in FPGA_ROBOTICS_FAST_TIER): the same check as in the test's
own process (slow_builds.py)."""

import os

if os.environ.get("FPGA_ROBOTICS_FAST_TIER"):
    import slow_builds

    slow_builds.forbid_on_import(os.environ["FPGA_ROBOTICS_FAST_TIER"])
