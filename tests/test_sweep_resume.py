"""``--resume`` after a scenario file was edited: the runs of the old file are run again and
their rows replaced (with their recordings), so the results hold each run of the campaign
once, judged by the file as it is now; and a design changed through a file it includes or
imports makes other runs."""

import csv
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fpga_robotics.sweep import api, load_campaign, run_campaign
from fpga_robotics.sweep.results import load_rows

DATA = Path(__file__).parent / "data"

#: A target walking away from a robot that cannot keep up: the mean distance grows, so the
#: check's limit decides the verdict. In 2 s the means are 2.2 m (0.2 m/s) and 2.49 m
#: (0.5 m/s), and no robot could get them under 1.72 and 2.02 m (mean_distance_floor_m):
#: 2.1 fails both, 2.3 the fast one (a faster walker would leave the check n/a).
SCENARIO = """name = "walkaway"
[room]
width = 20.0
depth = 4.0
[robot]
start = [1.5, 2.0]
heading_deg = 0.0
[[people]]
name = "runner"
waypoints = [[3.5, 2.0], [19.0, 2.0]]
speed = 1.0
loop = false
[checks]
mean_distance_max_m = {limit}
"""


def _campaign(path):
    return load_campaign(
        {
            "scenarios": [str(path)],
            "seeds": [0, 1],
            "backend": "model",
            "resolution": "40x24",
            "duration": 2.0,
            "grid": {"people.0.speed": [0.2, 0.5]},
        }
    )


def _limits(rows):
    """Each run's (seed, speed) -> the mean-distance limit its row was judged by."""
    out = {}
    for row in rows:
        [check] = [c for c in json.loads(row["checks_json"]) if c["name"] == "mean_distance_max_m"]
        out[(row["seed"], row["people.0.speed"])] = check["limit"]
    return out


def test_resume_after_editing_the_scenario_replaces_the_runs_of_the_old_file(tmp_path):
    scenario = tmp_path / "walkaway.toml"
    out = tmp_path / "out"
    runs = {(seed, speed) for seed in (0, 1) for speed in (0.2, 0.5)}

    # A limit no run meets: every run fails and is recorded.
    scenario.write_text(SCENARIO.format(limit=2.1))
    first = run_campaign(_campaign(scenario), out, workers=1, record="failing")
    assert len(first) == 4 and {r["status"] for r in first} == {"fail"}
    old_ids = {r["run_id"] for r in first}
    assert {p.stem for p in (out / "recordings").iterdir()} == old_ids

    # A limit every run meets: the same runs, judged again by the new file.
    scenario.write_text(SCENARIO.format(limit=50.0))
    rows = run_campaign(_campaign(scenario), out, workers=1, record="failing", resume=True)
    assert len(rows) == 4 and {r["status"] for r in rows} == {"pass"}
    assert not {r["run_id"] for r in rows} & old_ids
    assert _limits(rows) == dict.fromkeys(runs, 50.0)
    # Every reader sees each run once: the journal, the CSV table, the rows read back.
    assert len((out / "results.jsonl").read_text().splitlines()) == 4
    with open(out / "results.csv", newline="") as f:
        table = list(csv.DictReader(f))
    assert sorted((int(r["seed"]), float(r["people.0.speed"])) for r in table) == sorted(runs)
    assert _limits(load_rows(out)) == dict.fromkeys(runs, 50.0)
    # The old runs' recordings went with their rows (the new runs pass: none recorded).
    assert list((out / "recordings").iterdir()) == []

    # Resuming the file as it is runs nothing; --max-runs limits what runs, not what is kept.
    again = run_campaign(
        _campaign(scenario), out, workers=1, record="failing", resume=True, max_runs=1
    )
    assert sorted(r["run_id"] for r in again) == sorted(r["run_id"] for r in rows)
    assert json.loads((out / "campaign.json").read_text())["ran"] == 0


def _without(row, *keys):
    return {k: v for k, v in row.items() if k not in keys}


def test_resume_records_the_kept_runs_the_new_record_option_asks_for(tmp_path):
    """Kept runs of a campaign that recorded less (``--record none``) get the recordings and
    bags a resumed ``--record``/``--bag`` asks for, with their rows otherwise unchanged."""
    scenario = tmp_path / "walkaway.toml"
    out = tmp_path / "out"
    # The slow target stays within 2.3 m on average, the fast one does not.
    scenario.write_text(SCENARIO.format(limit=2.3))
    campaign = load_campaign(
        {
            "scenarios": [str(scenario)],
            "seeds": [0],
            "backend": "model",
            "resolution": "40x24",
            "duration": 2.0,
            "grid": {"people.0.speed": [0.2, 0.5]},
        }
    )
    first = {r["run_id"]: r for r in run_campaign(campaign, out, workers=1, record="none")}
    assert sorted(r["status"] for r in first.values()) == ["fail", "pass"]
    assert not (out / "recordings").exists()

    # --record failing: the failing run is recorded now, the passing one is not.
    rows = {r["run_id"]: r for r in run_campaign(campaign, out, workers=1, resume=True)}
    for run_id, row in rows.items():
        assert _without(row, "recording") == _without(first[run_id], "recording")
        wanted = f"recordings/{run_id}.rrd" if row["status"] == "fail" else ""
        assert row["recording"] == wanted
    assert [p.name for p in (out / "recordings").iterdir()] == [
        f"{r}.rrd" for r in rows if rows[r]["status"] == "fail"
    ]
    assert json.loads((out / "campaign.json").read_text())["ran"] == 0

    # --record all --bag: every kept run gets its recording and its bag.
    rows = run_campaign(campaign, out, workers=1, resume=True, record="all", bag=True)
    for row in rows:
        assert row["recording"] == f"recordings/{row['run_id']}.rrd"
        assert row["bag"] == f"bags/{row['run_id']}"
        assert (out / row["recording"]).is_file()
        assert (out / row["bag"] / "metadata.yaml").is_file()
        assert _without(row, "recording", "bag") == _without(first[row["run_id"]], "recording")

    # Everything asked for is there: resuming again runs and records nothing (the journal
    # holds the two kept rows, no line was added).
    run_campaign(campaign, out, workers=1, resume=True, record="all", bag=True)
    assert len((out / "results.jsonl").read_text().splitlines()) == 2


def test_a_campaign_without_resume_drops_the_earlier_recordings_and_bags_with_their_rows(
    tmp_path, monkeypatch
):
    """Without ``--resume`` the earlier rows go, and so do their recordings, bags and
    report: each file in the folder describes a row that is there."""
    scenario = tmp_path / "walkaway.toml"
    out = tmp_path / "out"
    scenario.write_text(SCENARIO.format(limit=2.3))  # the slow target passes, the fast fails
    campaign = load_campaign(
        {
            "scenarios": [str(scenario)],
            "seeds": [0],
            "backend": "model",
            "resolution": "40x24",
            "duration": 2.0,
            "grid": {"people.0.speed": [0.2, 0.5]},
        }
    )
    first = run_campaign(campaign, out, workers=1, record="all", bag=True)
    assert len(list((out / "recordings").iterdir())) == 2
    assert len(list((out / "bags").iterdir())) == 2
    assert (out / "report.html").is_file()

    # Interrupted before its first run finished: no row, so no file of the earlier runs.
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(api, "run_plan", interrupted)
        with pytest.raises(KeyboardInterrupt):
            run_campaign(campaign, out, workers=1, record="failing")
    assert load_rows(out) == []
    assert sorted(p.name for p in out.iterdir()) == [
        "bags",
        "campaign.json",
        "recordings",
        "results.csv",
        "results.jsonl",
        "results.parquet",
    ]
    assert list((out / "recordings").iterdir()) == list((out / "bags").iterdir()) == []
    assert json.loads((out / "campaign.json").read_text())["missing"] == 2

    # The same runs again, recording the failing one only: its recording is the only file.
    rows = run_campaign(campaign, out, workers=1, record="failing")
    assert {r["run_id"] for r in rows} == {r["run_id"] for r in first}
    [failing] = [r for r in rows if r["status"] == "fail"]
    named = {r["recording"] for r in load_rows(out) if r["recording"]}
    assert named == {f"recordings/{failing['run_id']}.rrd"}
    assert {f"recordings/{p.name}" for p in (out / "recordings").iterdir()} == named
    assert list((out / "bags").iterdir()) == []


#: A campaign's run identities, printed by a fresh interpreter: a design's imports are modules
#: of the process that plans, and a new one reads their files as they are now.
PLAN_IDS = (
    "import sys\n"
    "from fpga_robotics.sweep import load_campaign_file\n"
    "from fpga_robotics.sweep.plan import make_plan\n"
    "plan = make_plan(load_campaign_file(sys.argv[1]))\n"
    "print(' '.join(plan.ids[s] for s in plan.runs))\n"
)

#: A bumper stop of one's own whose speed comes from a module next to it.
GUARD = """import sys
from pathlib import Path

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

sys.path.insert(0, str(Path(__file__).parent))
from helper import SPEED  # noqa: E402


class Guard(wiring.Component):
    pressed: In(1)
    motor_left: Out(signed(16))
    motor_right: Out(signed(16))

    def elaborate(self, platform):
        m = Module()
        hit = Signal()
        with m.If(self.pressed):
            m.d.sync += hit.eq(1)
        m.d.comb += [self.motor_left.eq(Mux(hit, 0, SPEED)), self.motor_right.eq(self.motor_left)]
        return m
"""


def test_a_run_is_another_run_after_a_change_to_a_file_its_design_includes_or_imports(tmp_path):
    # What --resume keeps goes by the runs' identities: a design changed through a file the
    # campaign does not name must not keep its old rows.
    for name in ("bump_wall.toml", "bump_stop_ports.toml"):
        shutil.copy(DATA / name, tmp_path / name)
    verilog = (DATA / "bump_stop.v").read_text()
    (tmp_path / "inc.v").write_text(
        verilog.replace(");\n  reg hit;", ');\n  `include "speed.vh"\n  reg hit;').replace(
            "12'sd300", "SPEED"
        )
    )
    (tmp_path / "speed.vh").write_text("localparam signed [11:0] SPEED = 12'sd300;\n")
    (tmp_path / "guard.py").write_text(GUARD)
    (tmp_path / "helper.py").write_text("SPEED = 300\n")
    (tmp_path / "c.toml").write_text(
        'scenarios = ["bump_wall.toml"]\n[[sets]]\n"design.top" = "verilog:inc.v"\n'
        '"design.ports" = "bump_stop_ports.toml"\n[[sets]]\n"design.top" = "guard.py:Guard"\n'
    )

    def ids():
        done = subprocess.run(
            [sys.executable, "-c", PLAN_IDS, "c.toml"],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=120,
            check=True,
        )
        return done.stdout.split()

    verilog_run, amaranth_run = ids()
    # The Verilog design's `include file changes: its run is another run, the other is not.
    (tmp_path / "speed.vh").write_text("localparam signed [11:0] SPEED = 12'sd100;\n")
    verilog_now, amaranth_now = ids()
    assert verilog_now != verilog_run and amaranth_now == amaranth_run
    # The module the Amaranth design imports changes: the other way round.
    (tmp_path / "helper.py").write_text("SPEED = 100\n")
    verilog_later, amaranth_later = ids()
    assert verilog_later == verilog_now and amaranth_later != amaranth_run
