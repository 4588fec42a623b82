"""Campaign runs that differ only in their design are grouped by world and run as one
reference run and forked variants: the rows are those of the runs made in full."""

from pathlib import Path

from fpga_robotics.checks.summary import TIMING_FIELDS
from fpga_robotics.sweep import load_campaign, run_campaign, runner
from fpga_robotics.sweep.fork_groups import execute_group, fork_groups, spread
from fpga_robotics.sweep.plan import make_plan

#: Two seeds, four designs each (when to search and which way), and a heavier robot (another
#: world) for one of them.
CAMPAIGN = {
    "name": "forked",
    "scenarios": ["lost_target"],
    "seeds": "0-1",
    "backend": "model",
    "resolution": "80x60",
    "duration": 6.0,
    "grid": {"design.lost_frames": [5, 15], "design.search_dps": [-300, 250]},
    "sets": [{"robot.mass": 8.0, "design.lost_frames": 5}],
}

#: A design of one's own that ``sim.timing = "auto"`` runs in real-clock timing.
NEAR_RED = Path(__file__).parent / "data" / "user_designs" / "near_red.py"

#: Row fields that measure the machine, not the run.
TIMES = {"wall_s", "cpu_s", "run_s", *TIMING_FIELDS}


def test_runs_are_grouped_by_world_and_seed():
    plan = make_plan(load_campaign(dict(CAMPAIGN)))
    groups = fork_groups(plan.runs, plan.worlds)
    sizes = sorted(len(g) for g in groups)
    # Per seed: the four grid designs in one world; the heavier robot's world alone.
    assert sizes == [1, 1, 4, 4]
    for group in groups:
        assert len({s.seed for s in group}) == 1
        assert len({dict(s.overrides).get("robot.mass") for s in group}) == 1


def test_forked_rows_are_the_full_runs_rows(tmp_path):
    campaign = load_campaign(dict(CAMPAIGN))
    forked = run_campaign(campaign, tmp_path / "forked", workers=1, record="none")
    full = run_campaign(campaign, tmp_path / "full", workers=1, record="none", fork=False)

    def by_id(rows):
        return {r["run_id"]: {k: v for k, v in r.items() if k not in TIMES} for r in rows}

    a, b = by_id(forked), by_id(full)
    assert len(a) == 10 and a.keys() == b.keys()
    for run_id, row in a.items():
        assert row == b[run_id], row["replay"]
    # The designs did part: not every run of a seed drove the same path.
    paths = {(r["seed"], r["path_length_m"]) for r in a.values()}
    assert len(paths) > 2


def test_a_worker_death_in_a_group_loses_only_the_run_in_progress(tmp_path, monkeypatch):
    # The runs with search_dps 250 end their worker process: in the group of one seed's four
    # designs, the second and the fourth. The first finished before the death and keeps its
    # row; the third, never started, is run after it; each dying run alone is an error, as
    # when every run is made in full.
    monkeypatch.setenv("FPGA_ROBOTICS_SWEEP_FAULT", "exit@0+design.search_dps=250")
    grid_only = {k: v for k, v in CAMPAIGN.items() if k != "sets"}
    campaign = load_campaign({**grid_only, "seeds": [0], "duration": 3.0})
    plan = make_plan(campaign)
    assert [len(g) for g in fork_groups(plan.runs, plan.worlds)] == [4]
    forked = run_campaign(campaign, tmp_path / "forked", workers=1, record="none")
    full = run_campaign(campaign, tmp_path / "full", workers=1, record="none", fork=False)

    def by_id(rows):
        return {r["run_id"]: {k: v for k, v in r.items() if k not in TIMES} for r in rows}

    a, b = by_id(forked), by_id(full)
    assert a == b
    died = sorted(r["design.search_dps"] for r in a.values() if r["status"] == "error")
    assert died == [250, 250]
    assert {r["message"] for r in a.values() if r["status"] == "error"} == {
        "the worker running it died (a crash or a kill)"
    }


def test_runs_whose_designs_resolve_to_two_timings_share_no_world():
    # sim.timing = "auto" is resolved by the design: one camera design on frames, another on
    # pins share every scenario section, yet cannot be forked from one another.
    import dataclasses

    import pytest

    from fpga_robotics.loop.fork import check_same_world
    from fpga_robotics.scenario.load import load_scenario
    from fpga_robotics.sweep import runner
    from fpga_robotics.sweep.fork_groups import world_key

    args, frames, shadow = runner.load_run(["--scenario", "follow_person"])
    assert frames.sim.timing == "compressed"
    pins = dataclasses.replace(frames, sim=dataclasses.replace(frames.sim, timing="real_clock"))
    assert world_key(args, frames, shadow) != world_key(args, pins, shadow)
    same = load_scenario("follow_person")
    check_same_world(frames, same)  # the same timing: forkable
    with pytest.raises(ValueError, match="a variant runs in real_clock timing, the reference"):
        check_same_world(frames, pins)


def test_designs_resolved_to_two_timings_are_not_forked_from_one_another(tmp_path):
    # One world for both designs, but "auto" runs FollowTarget in compressed timing and
    # NearRed in real-clock timing: neither can be a variant of the other.
    campaign = load_campaign(
        {
            "name": "timings",
            "scenarios": ["lost_target"],
            "seeds": [0],
            "duration": 1.0,
            "resolution": "40x30",
            "set": ["sim.clock_hz=200000", "camera.fps=10"],
            "grid": {"design.top": ["follow_target", f"{NEAR_RED}:NearRed"]},
        }
    )
    plan = make_plan(campaign)
    assert [len(g) for g in fork_groups(plan.runs, plan.worlds)] == [1, 1]
    forked = run_campaign(campaign, tmp_path / "forked", workers=1, record="none")
    full = run_campaign(campaign, tmp_path / "full", workers=1, record="none", fork=False)

    def by_id(rows):
        return {r["run_id"]: {k: v for k, v in r.items() if k not in TIMES} for r in rows}

    assert by_id(forked) == by_id(full)
    assert {r["status"] for r in forked} <= {"pass", "fail"}


def test_a_run_in_another_timing_than_the_reference_is_run_in_full():
    # A group given runs in two timings (FollowTarget compressed, NearRed real clock): the
    # second is no variant of the first, and gets the row of its own full run.
    scenario = str(NEAR_RED.with_suffix(".toml"))
    run = ["--scenario", scenario, "--seed", "0", "--duration", "1.0"]
    argvs = [
        [
            *run,
            "--backend",
            "model",
            "--set",
            'design.top="follow_target"',
            "--set",
            "design.params={}",
        ],
        [*run, "--backend", "cxxrtl"],
    ]
    grouped = execute_group(argvs, [None, None], ["follow_target", "near_red"])
    for argv, outcome in zip(argvs, grouped, strict=True):
        alone = runner.execute(argv)
        assert outcome["status"] == alone["status"] != "error", outcome["message"]
        mine, theirs = (
            {k: v for k, v in o["summary"].items() if k not in TIMING_FIELDS}
            for o in (outcome, alone)
        )
        assert mine == theirs


def test_spread_cuts_groups_for_idle_workers_keeping_every_run_once_in_order():
    one = list(range(20))
    assert spread([one], 2) == [one[:10], one[10:]]
    assert [len(g) for g in spread([one], 3)] == [7, 7, 6]
    # The largest pieces are cut first; a run alone cannot be cut.
    assert [len(g) for g in spread([one, ["a"]], 4)] == [7, 7, 6, 1]
    assert spread([["a"], ["b"]], 4) == [["a"], ["b"]]
    # Enough groups already: none is cut (each cut costs a reference run).
    assert spread([one[:4], one[4:]], 2) == [one[:4], one[4:]]
    assert [r for g in spread([one, ["a", "b"]], 5) for r in g] == [*one, "a", "b"]


def test_a_single_world_is_forked_on_every_worker_with_the_full_runs_rows(tmp_path):
    # One seed, four designs: one world, cut in two for two workers (a reference each).
    grid_only = {k: v for k, v in CAMPAIGN.items() if k != "sets"}
    campaign = load_campaign({**grid_only, "seeds": [0], "duration": 3.0})
    plan = make_plan(campaign)
    assert [len(g) for g in spread(fork_groups(plan.runs, plan.worlds), 2)] == [2, 2]
    forked = run_campaign(campaign, tmp_path / "forked", workers=2, record="none")
    full = run_campaign(campaign, tmp_path / "full", workers=2, record="none", fork=False)

    def by_id(rows):
        return {r["run_id"]: {k: v for k, v in r.items() if k not in TIMES} for r in rows}

    assert len(forked) == 4 and by_id(forked) == by_id(full)
