"""A campaign on an embedded 2-process Dask cluster: the same summaries as the runs made one
by one with ``run_scenario``; each row's replay command reproduces its summary; a run that
raises, one that hangs and one that kills its worker are recorded while the rest complete."""

import json
import shlex
import subprocess
import sys

import pytest

from fpga_robotics.checks.summary import TIMING_FIELDS
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sweep import load_campaign, report_dir, run_campaign

#: Small and fast: the model backend, tiny frames, short runs.
SMALL = {
    "name": "small",
    "scenarios": ["approach", "follow_person"],
    "seeds": "0-1",
    "backend": "model",
    "resolution": "40x24",
    "duration": 2.0,
    "grid": {"design.diff_min": [4, 8]},
    "sets": [{"robot.mass": 8.0}],
    # Two seconds cannot bring approach's mean distance from its 2.0 m start under 1.75 m.
    "set": ["checks.mean_distance_max_m=3.0"],
}

#: Summary fields that are not simulation results (the machine's timing, the run's label).
NOT_COMPARED = {*TIMING_FIELDS, "scenario", "seed", "collisions", "checks", "overrides"}


def _direct(scenario, seed, diff_min=None, mass=None):
    overrides = ['camera.resolution="40x24"', "sim.duration=2.0", "checks.mean_distance_max_m=3.0"]
    if diff_min is not None:
        overrides.append(f"design.diff_min={diff_min}")
    if mass is not None:
        overrides.append(f"robot.mass={mass}")
    sc = load_scenario(scenario, overrides)
    return run_scenario(sc, seed=seed, backend="model").summary


def _assert_row_matches(row, summary):
    for key, value in summary.items():
        if key not in NOT_COMPARED:  # lists and tables are JSON text in the tables
            got = json.loads(row[key]) if isinstance(value, (list, dict)) else row[key]
            assert got == value, key
    for kind, n in summary["collisions"].items():
        assert row[f"collisions_{kind}"] == n
    for check in summary["checks"]:
        assert row[f"check_{check['name']}"] == check["passed"]
    assert row["status"] == summary["verdict"]


@pytest.fixture(scope="module")
def small_campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("small")
    rows = run_campaign(load_campaign(dict(SMALL)), out, workers=2, record="failing")
    return out, rows


def test_two_workers_give_the_summaries_of_runs_made_one_by_one(small_campaign):
    out, rows = small_campaign
    assert len(rows) == 2 * (2 + 1) * 2  # scenarios x (grid + the set) x seeds
    assert {
        (r["scenario"], r.get("design.diff_min"), r.get("robot.mass"), r["seed"]) for r in rows
    } == {
        (s, d, m, seed)
        for s in ("approach", "follow_person")
        for d, m in ((4, None), (8, None), (None, 8.0))
        for seed in (0, 1)
    }
    for row in rows:
        _assert_row_matches(
            row,
            _direct(
                row["scenario"], row["seed"], row.get("design.diff_min"), row.get("robot.mass")
            ),
        )
    # The tables hold the same rows as the run returned.
    import pyarrow.parquet as pq

    table = pq.read_table(out / "results.parquet").to_pylist()
    assert sorted(r["run_id"] for r in table) == sorted(r["run_id"] for r in rows)
    assert len((out / "results.csv").read_text().splitlines()) == len(rows) + 1
    html = (out / "report.html").read_text()
    assert "data:image/png;base64," in html and "<script" not in html
    # No run sets both design.diff_min (the grid) and robot.mass (the set): no heatmap.
    assert "design.diff_min x robot.mass" not in html
    # The report names every axis, with the runs of the other kind as "(not set)".
    summary = report_dir(out)
    assert "pass rate per design.diff_min:" in summary and "pass rate per robot.mass:" in summary
    assert "(not set)" in summary


def test_failing_runs_have_their_recording(small_campaign):
    out, rows = small_campaign
    failing = [r for r in rows if r["status"] == "fail"]
    assert failing and len(failing) < len(rows)
    for row in rows:
        if row["status"] == "fail":
            rrd = out / row["recording"]
            assert rrd.name == f"{row['run_id']}.rrd" and rrd.stat().st_size > 1000
        else:
            assert row["recording"] == ""
    assert sorted(p.name for p in (out / "recordings").iterdir()) == sorted(
        f"{r['run_id']}.rrd" for r in failing
    )
    # results.jsonl: one line per run, a failing run's with its recording.
    lines = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert sorted(r["run_id"] for r in lines) == sorted(r["run_id"] for r in rows)
    for line in lines:
        failed = line["run_id"] in {r["run_id"] for r in failing}
        assert line["recording"] == (f"recordings/{line['run_id']}.rrd" if failed else "")


def test_replay_command_reproduces_the_summary(small_campaign, tmp_path):
    _out, rows = small_campaign
    for row in (rows[0], next(r for r in rows if r["status"] == "fail")):
        argv = shlex.split(row["replay"])
        assert argv[:3] == ["python", "-m", "fpga_robotics.run"]
        summary_path = tmp_path / f"{row['run_id']}.json"
        proc = subprocess.run(
            [
                sys.executable,
                *argv[1:],
                "--rerun",
                "off",
                "--quiet",
                "--summary",
                str(summary_path),
            ],
            check=False,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert proc.returncode == (0 if row["status"] == "pass" else 1), proc.stderr
        _assert_row_matches(row, json.loads(summary_path.read_text()))


def test_raising_hanging_and_dying_runs_are_recorded_and_the_rest_complete(tmp_path, monkeypatch):
    # Worker processes inherit the environment: seed 1 raises, seed 2 hangs inside a frame
    # (its worker is ended after the timeout), seed 3 ends its worker process.
    monkeypatch.setenv("FPGA_ROBOTICS_SWEEP_FAULT", "raise@1,hang@2,exit@3")
    grid_only = {k: v for k, v in SMALL.items() if k != "sets"}
    campaign = load_campaign(
        {**grid_only, "scenarios": ["approach"], "seeds": "0-5", "grid": {"design.diff_min": [4]}}
    )
    rows = run_campaign(campaign, tmp_path, workers=2, record="none", timeout=3.0)
    by_seed = {r["seed"]: r for r in rows}
    assert sorted(by_seed) == [0, 1, 2, 3, 4, 5]
    assert by_seed[1]["status"] == "error" and "injected fault" in by_seed[1]["message"]
    assert by_seed[2]["status"] == "timeout" and "timeout" in by_seed[2]["message"]
    assert by_seed[3]["status"] == "error" and "worker" in by_seed[3]["message"]
    for seed in (0, 4, 5):
        _assert_row_matches(by_seed[seed], _direct("approach", seed, 4))


def test_the_campaign_files_timeout_limits_each_run(tmp_path, monkeypatch):
    # A run that hangs is ended after the file's `timeout`, not the default (at least 30 s).
    monkeypatch.setenv("FPGA_ROBOTICS_SWEEP_FAULT", "hang@1")
    grid_only = {k: v for k, v in SMALL.items() if k != "sets"}
    campaign = load_campaign(
        {
            **grid_only,
            "scenarios": ["approach"],
            "seeds": [1],
            "timeout": 2.0,
            "grid": {"design.diff_min": [4]},
        }
    )
    [row] = run_campaign(campaign, tmp_path, workers=1, record="none")
    assert row["status"] == "timeout"
    assert "per-run timeout of 2 s" in row["message"], row["message"]


def test_a_campaign_with_a_shadow_design_reports_where_it_differs(tmp_path):
    from fpga_robotics.cli.run import _shadow_params
    from fpga_robotics.loop.compressed import make_backend

    campaign = load_campaign(
        {
            "scenarios": ["approach"],
            "seeds": [3],
            "backend": "model",
            "duration": 1.0,
            "shadow": "published",
        }
    )
    [row] = run_campaign(campaign, tmp_path, workers=1, record="none")
    assert "--shadow published" in row["replay"]
    scenario = load_scenario("approach", ["sim.duration=1.0"])
    shadow = make_backend("model", _shadow_params(scenario, "published"))
    try:
        direct = run_scenario(
            scenario, seed=3, backend="model", shadow=shadow, shadow_label="published"
        ).summary
    finally:
        shadow.close()
    assert direct["shadow"]["differing_frames"]["motor_left"] > 0  # the designs differ
    _assert_row_matches(row, direct)


def test_a_campaign_with_a_shadow_design_on_pins_runs_it_as_run_does(tmp_path, monkeypatch):
    # --shadow REF in real-clock timing: a second design on pins beside the primary, as
    # `run --shadow REF` runs it (the same design: no frame differs).
    from pathlib import Path

    from fpga_robotics.loop.real_clock import make_pin_backend

    data = Path(__file__).parent / "data" / "user_designs"
    monkeypatch.chdir(data)
    campaign = load_campaign(
        {
            "scenarios": [str(data / "wall_stop.toml")],
            "seeds": [0, 1],
            "duration": 2.0,
            "shadow": "wall_stop.py:WallStop",
        }
    )
    rows = run_campaign(campaign, tmp_path, workers=1, record="none")
    assert len(rows) == 2
    for row in rows:
        assert row["status"] == "pass", row["message"]
        scenario = load_scenario(str(data / "wall_stop.toml"), ["sim.duration=2.0"])
        with (
            make_pin_backend("auto", scenario) as design,
            make_pin_backend("auto", scenario) as shadow,
        ):
            direct = run_scenario(
                scenario,
                seed=row["seed"],
                backend=design,
                shadow=shadow,
                shadow_label="wall_stop.py:WallStop",
            ).summary
        assert not any(direct["shadow"]["differing_frames"].values())
        _assert_row_matches(row, direct)


def _report_row(scenario, status, **overrides):
    return {
        "run_id": f"{len(overrides)}{status}{sorted(overrides.items())}",
        "scenario": scenario,
        "seed": 0,
        "status": status,
        "message": "",
        "failed_checks": "found_min_fraction" if status == "fail" else "",
        "na_checks": "",
        "replay": "python -m fpga_robotics.run",
        "recording": "",
        **overrides,
    }


def test_the_pass_rates_show_axis_values_as_the_campaign_writes_them():
    from fpga_robotics.sweep.report import format_report

    rows = [
        # A list is its JSON text in a row (results._cell), a bool a bool.
        _report_row("one", "pass", **{"design.params.reverse": True, "design.params.t": "[1, 2]"}),
        _report_row("one", "fail", **{"design.params.reverse": False, "design.params.t": None}),
    ]
    text = format_report(rows, ["design.params.reverse", "design.params.t"])
    assert "  true " in text and "  false " in text and "True" not in text
    assert "  [1, 2] " in text and "  (not set) " in text


def test_the_report_maps_pass_rates_only_of_runs_that_set_both_axes(tmp_path):
    from fpga_robotics.sweep.report import write_html

    def heatmaps(rows):
        """How many maps the report of ``rows`` (axes a and b) draws under their heading."""
        write_html(tmp_path / "report.html", rows, ["a", "b"], {"name": "t"})
        page = (tmp_path / "report.html").read_text()
        if "<h2>a x b</h2>" not in page:
            return 0
        section = page[page.index("<h2>a x b</h2>") : page.index("<h2>Metric distributions")]
        return section.count("<img ")

    # A grid of two axes: one map per scenario.
    grid = [
        _report_row(s, "pass" if a == 4 else "fail", a=a, b=b)
        for s in ("one", "two")
        for a in (4, 8)
        for b in (0.5, 1.0)
    ]
    assert heatmaps(grid) == 2
    # [[sets]] tables of one key each (robustness's shape): no run sets both, no map.
    sets = [_report_row("one", "pass", a=4), _report_row("one", "fail", b=1.0)]
    assert heatmaps(sets) == 0
    # Only the scenario whose runs set both gets a map.
    assert heatmaps(sets + grid[4:]) == 1
