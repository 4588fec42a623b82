"""Ctrl-C stops a campaign cleanly (exit 130, every finished run kept, no worker left), and
``--resume`` then runs only the missing runs."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest
from terminal_signals import FROM_A_TERMINAL

from fpga_robotics.sweep import report_dir
from fpga_robotics.sweep.results import load_rows

#: 16 runs of about half a second each on the model backend: long enough to interrupt.
CAMPAIGN = """scenarios = ["follow_person"]
seeds = "0-15"
backend = "model"
resolution = "40x24"
duration = 20.0
"""
SWEEP = [
    sys.executable,
    "-m",
    "fpga_robotics.sweep",
    "c.toml",
    "--workers",
    "2",
    "--out",
    "out",
    "--quiet",
    "--record",
    "none",
]


def _processes_in(folder):
    """Live processes whose working folder is ``folder`` (the campaign's workers are)."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            if os.readlink(f"/proc/{pid}/cwd") == str(folder):
                found.append(pid)
        except OSError:
            continue
    return found


def _journal_lines(path):
    try:
        return len(path.read_text().splitlines())
    except OSError:
        return 0


def test_ctrl_c_keeps_finished_runs_and_resume_runs_the_rest(tmp_path):
    (tmp_path / "c.toml").write_text(CAMPAIGN)
    journal = tmp_path / "out" / "results.jsonl"
    # A terminal's Ctrl-C reaches the whole process group: the command and its workers.
    proc = subprocess.Popen(
        SWEEP,
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        **FROM_A_TERMINAL,
    )
    try:
        end = time.monotonic() + 120
        while _journal_lines(journal) < 2 and time.monotonic() < end:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        _out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 130, err
    assert "interrupted" in err and "--resume" in err
    assert "Traceback" not in err
    end = time.monotonic() + 20  # the workers are gone (their nannies end them)
    while _processes_in(tmp_path) and time.monotonic() < end:
        time.sleep(0.1)
    assert _processes_in(tmp_path) == []
    kept = {r["run_id"]: r for r in load_rows(tmp_path / "out")}
    assert 2 <= len(kept) < 16
    assert all(r["status"] in ("pass", "fail") for r in kept.values())
    # The report of the partial campaign says so, in report.html and `sweep report`.
    headline = f"{len(kept)} of 16 runs (the campaign was interrupted; continue it with --resume)"
    assert f"<b>{headline}: " in (tmp_path / "out" / "report.html").read_text()
    assert report_dir(tmp_path / "out").startswith(f"{headline}: ")

    proc = subprocess.run(
        SWEEP + ["--resume"], cwd=tmp_path, check=False, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode in (0, 1), proc.stderr
    rows = {r["run_id"]: r for r in load_rows(tmp_path / "out")}
    assert len(rows) == 16 and sorted({r["seed"] for r in rows.values()}) == list(range(16))
    # The runs kept were not run again: their rows (with their own timings) are unchanged.
    for run_id, row in kept.items():
        assert rows[run_id] == row
    meta = json.loads((tmp_path / "out" / "campaign.json").read_text())
    assert meta["ran"] == 16 - len(kept)
    assert meta["missing"] == 0
    assert "16 runs:" in proc.stdout
    assert "<b>16 runs: " in (tmp_path / "out" / "report.html").read_text()


def test_ctrl_c_while_the_report_is_drawn_leaves_no_stale_report(tmp_path, monkeypatch, capsys):
    """Ctrl-C after the runs, while report.html is drawn: the rows are kept, the report of an
    earlier campaign in the folder is not left to describe them, and the closing line says
    how to draw it."""
    from fpga_robotics.cli import sweep as cli
    from fpga_robotics.sweep import api

    (tmp_path / "c.toml").write_text(CAMPAIGN.replace('"0-15"', "[0]").replace("20.0", "1.0"))
    monkeypatch.chdir(tmp_path)
    argv = ["c.toml", "--workers", "1", "--out", "out", "--quiet", "--record", "none"]
    assert cli.main(argv) == 1  # follow_person in 1 s: its checks fail
    assert (tmp_path / "out" / "report.html").is_file()

    def interrupted(*_args):
        raise KeyboardInterrupt

    monkeypatch.setattr(api, "write_html", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cli.main([*argv, "--resume"])
    assert not (tmp_path / "out" / "report.html").exists()
    assert len(load_rows(tmp_path / "out")) == 1
    err = capsys.readouterr().err
    assert "no report.html: `fpga-robotics sweep report out` writes it" in err
