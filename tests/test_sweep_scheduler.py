"""The same campaign through ``--scheduler``: a real ``dask scheduler`` and ``dask worker``
started as subprocesses on 127.0.0.1 (free ports, bounded in time, always torn down)."""

import json
import os
import signal
import socket
import subprocess
import sys
import time

from fpga_robotics.sweep import load_campaign, run_campaign
from fpga_robotics.sweep.results import load_rows

CAMPAIGN = """scenarios = ["approach"]
seeds = "0-3"
backend = "model"
resolution = "40x24"
duration = 2.0
"""


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_for_port(port, proc, timeout):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        assert proc.poll() is None, "the Dask process ended early"
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise AssertionError(f"nothing listens on port {port} after {timeout} s")


def _stop(proc):
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=15)


def test_campaign_on_a_real_scheduler_matches_the_embedded_cluster(tmp_path):
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = [sys.executable, "-m", "dask"]
    quiet = {
        "stdout": subprocess.DEVNULL,
        "stderr": subprocess.DEVNULL,
        "start_new_session": True,
        "cwd": tmp_path,
    }
    scheduler = subprocess.Popen(
        dask + ["scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"], **quiet
    )
    worker = None
    try:
        _wait_for_port(port, scheduler, 60)
        worker = subprocess.Popen(
            dask
            + [
                "worker",
                address,
                "--nworkers",
                "2",
                "--nthreads",
                "1",
                "--no-dashboard",
                "--host",
                "127.0.0.1",
            ],
            **quiet,
        )
        (tmp_path / "c.toml").write_text(CAMPAIGN)
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "fpga_robotics.sweep",
                "c.toml",
                "--scheduler",
                address,
                "--out",
                "remote",
                "--quiet",
                "--record",
                "none",
            ],
            cwd=tmp_path,
            check=False,
            capture_output=True,
            text=True,
            timeout=180,
        )
        assert proc.returncode in (0, 1), proc.stderr
        assert "4 runs:" in proc.stdout
        meta = json.loads((tmp_path / "remote" / "campaign.json").read_text())
        assert meta["scheduler"] == address and meta["workers"] >= 1
    finally:
        if worker is not None:
            _stop(worker)
        _stop(scheduler)
    remote = {r["run_id"]: r for r in load_rows(tmp_path / "remote")}
    local = {
        r["run_id"]: r
        for r in run_campaign(
            load_campaign(__import__("tomllib").loads(CAMPAIGN)),
            tmp_path / "local",
            workers=2,
            record="none",
        )
    }
    assert sorted(remote) == sorted(local) and len(remote) == 4
    timing = {
        "wall_s",
        "cpu_s",
        "run_s",
        "wall_time_s",
        "ms_per_frame",
        "realtime_factor",
        "cpu_ms_per_frame",
        "cycles_per_wall_s",
    }
    for run_id, row in remote.items():
        assert {k: v for k, v in row.items() if k not in timing} == {
            k: v for k, v in local[run_id].items() if k not in timing
        }
