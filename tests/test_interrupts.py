"""SIGTERM and Ctrl-C end a run cleanly: exit 143 / 130 with one line, the recording kept
under its own name, no temporary file, no compiler left running (issue: reliability)."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from terminal_signals import FROM_A_TERMINAL

from fpga_robotics.sim.backends import available_backends

RUN = [sys.executable, "-m", "fpga_robotics.run"]


def _processes_mentioning(text):
    """Command lines of live processes whose command line or working folder mentions
    ``text`` (a unique temporary path)."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
            cwd = os.readlink(f"/proc/{pid}/cwd")
        except OSError:
            continue
        if text in cmdline or text in cwd:
            found.append(f"{cmdline} (in {cwd})")
    return found


def _wait_for(predicate, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("sig, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_signal_mid_run_keeps_the_recording(sig, code, tmp_path):
    proc = subprocess.Popen(
        RUN
        + [
            "--backend",
            "model",
            "--duration",
            "3600",
            "--rerun",
            "save:rec.rrd",
            "--summary",
            "s.json",
            "--quiet",
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **FROM_A_TERMINAL,
    )
    try:
        # Frames are being written once the recording holds data.
        assert _wait_for(
            lambda: (
                any(p.stat().st_size > 100_000 for p in tmp_path.glob("*.rrd") if p.exists())
                or any(p.stat().st_size > 100_000 for p in tmp_path.glob(".*rrd"))
            ),
            timeout=120,
        ), "the run never started recording"
        proc.send_signal(sig)
        _out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == code, err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].endswith("terminated" if code == 143 else "interrupted")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rec.rrd"]  # no summary of a cut run

    from fpga_robotics.viz.readback import read_rrd

    assert read_rrd(tmp_path / "rec.rrd")  # complete enough to read back


@pytest.mark.slow
@pytest.mark.skipif("cxxrtl" not in available_backends(), reason="no C++ compiler")
def test_sigterm_during_a_compile_ends_the_compiler(tmp_path):
    cache = tmp_path / "cache"
    env = dict(os.environ, FPGA_ROBOTICS_CACHE=str(cache))
    # A resolution no other test builds, so this process compiles for sure.
    proc = subprocess.Popen(
        RUN
        + ["--backend", "cxxrtl", "--resolution", "200x96", "--duration", "1", "--rerun", "off"],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **FROM_A_TERMINAL,
    )
    try:
        # The compiler proper (cc1plus, started by the g++ driver) is at work in the cache.
        assert _wait_for(
            lambda: any("cc1plus" in p for p in _processes_mentioning(str(cache))), timeout=180
        ), "the compiler never started"
        time.sleep(1.5)  # well under way
        proc.send_signal(signal.SIGTERM)
        _out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert "compiling the cxxrtl model" in err  # the user was told why nothing moved
    assert _wait_for(lambda: not _processes_mentioning(str(cache)), timeout=1), (
        _processes_mentioning(str(cache))
    )
    leftovers = [p.name for p in cache.iterdir() if not p.name.endswith(".lock")]
    assert leftovers == []
