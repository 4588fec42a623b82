"""Campaign files to runs: seeds, the grid's cartesian product plus explicit sets, and the
``--set`` text of every value read back as the value itself."""

import itertools
import json
import tomllib

from hypothesis import given
from hypothesis import strategies as st

from fpga_robotics.scenario.load import _parse_value
from fpga_robotics.sweep import load_campaign, load_campaign_file
from fpga_robotics.sweep.campaign import parse_seeds, toml_value

SCALARS = (
    st.booleans()
    | st.integers(-(2**63), 2**63 - 1)
    | st.floats(allow_nan=False)
    | st.text(max_size=20)
)
VALUES = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4), max_leaves=10)


@given(VALUES)
def test_set_text_reads_back_as_the_value(value):
    assert _parse_value(toml_value(value)) == value


def test_seed_ranges_and_lists():
    assert parse_seeds("0-19") == list(range(20))
    assert parse_seeds("7") == [7] and parse_seeds(7) == [7]
    assert parse_seeds([5, 1, 5]) == [5, 1]


def test_runs_are_the_grid_product_plus_the_sets_for_every_scenario_and_seed():
    data = tomllib.loads("""
scenarios = ["approach", "divider"]
seeds = "0-2"
[grid]
"design.diff_min" = [4, 6]
lighting = {ambient = [0.3, 0.5, 0.7]}
[[sets]]
robot.mass = 12.0
""")
    campaign = load_campaign(data)
    assert campaign.axes == ["design.diff_min", "lighting.ambient", "robot.mass"]
    expected = [
        (sc, combo, seed)
        for sc in ("approach", "divider")
        for combo in [
            *(
                ((("design.diff_min", d), ("lighting.ambient", a)))
                for d, a in itertools.product((4, 6), (0.3, 0.5, 0.7))
            ),
            (("robot.mass", 12.0),),
        ]
        for seed in range(3)
    ]
    assert [(r.scenario, r.overrides, r.seed) for r in campaign.runs] == expected
    run = campaign.runs[0]
    assert run.argv() == [
        "--scenario",
        "approach",
        "--backend",
        "auto",
        "--seed",
        "0",
        "--set",
        "design.diff_min=4",
        "--set",
        "lighting.ambient=0.3",
    ]


def test_a_grid_axis_of_lists_plans_a_run_for_each_list():
    """A key whose value is a list (a start position, waypoints) as a grid axis or in a set:
    each run takes the whole list (it crashed the planner: a list is not hashable)."""
    from fpga_robotics.sweep.plan import make_plan

    data = tomllib.loads("""
scenarios = ["follow_person"]
seeds = "0"
[grid]
"robot.start" = [[0.5, 0.6], [0.9, 0.5]]
[[sets]]
"people.0.waypoints" = [[3.0, 2.0], [4.0, 2.0]]
""")
    campaign = load_campaign(data)
    plan = make_plan(campaign)
    sets = [[a for a in spec.argv() if "=" in a] for spec in plan.runs]
    assert sets == [
        ["robot.start=[0.5, 0.6]"],
        ["robot.start=[0.9, 0.5]"],
        ["people.0.waypoints=[[3.0, 2.0], [4.0, 2.0]]"],
    ]
    assert [_parse_value(s[0].partition("=")[2]) for s in sets] == [
        [0.5, 0.6],
        [0.9, 0.5],
        [[3.0, 2.0], [4.0, 2.0]],
    ]


def test_an_array_of_tables_as_a_grid_axis_or_in_a_set_plans_a_run_for_each_value():
    """Furniture (an array of tables) as a grid axis, in a set and in a known limit: each run
    loads the furniture given (the planner crashed: a table is not hashable), and its row
    cell is the value as JSON."""
    from fpga_robotics.sweep.plan import make_plan
    from fpga_robotics.sweep.report import known_limit
    from fpga_robotics.sweep.results import make_row
    from fpga_robotics.sweep.runner import load_run

    data = tomllib.loads("""
scenarios = ["follow_person"]
seeds = "0"
[grid]
"room.furniture" = [[{center = [4.0, 1.0]}], []]
[[sets]]
"room.furniture" = [{center = [2.0, 4.0], size = [0.5, 0.5]}]
[[known_limits]]
check = "found_min_fraction"
when = {"room.furniture" = [{center = [4.0, 1.0]}]}
reason = "the desk hides the target"
""")
    campaign = load_campaign(data)
    plan = make_plan(campaign)
    expected = [[{"center": [4.0, 1.0]}], [], [{"center": [2.0, 4.0], "size": [0.5, 0.5]}]]
    assert [load_run(spec.argv())[1].data["room"]["furniture"] for spec in plan.runs] == expected
    rows = [make_row(spec, "id", "follow_person", {"status": "pass"}) for spec in plan.runs]
    assert [json.loads(row["room.furniture"]) for row in rows] == expected
    limits = [known_limit(row, "found_min_fraction", campaign.known_limits) for row in rows]
    assert [entry is not None for entry in limits] == [True, False, False]


def test_an_absolute_scenario_path_stays_as_given(tmp_path, monkeypatch):
    # It became a path from the current folder (../../work/x.toml from /tmp/a/b), which the
    # replay commands printed.
    scenario = tmp_path / "s" / "mine.toml"
    scenario.parent.mkdir()
    scenario.write_text('name = "mine"\n')
    campaign = tmp_path / "c" / "c.toml"
    campaign.parent.mkdir()
    campaign.write_text(f'scenarios = ["{scenario}", "../s/mine.toml"]\nseeds = "0"\n')
    (tmp_path / "here").mkdir()
    monkeypatch.chdir(tmp_path / "here")
    runs = load_campaign_file(str(campaign)).runs
    assert [r.scenario for r in runs] == [str(scenario), "../s/mine.toml"]
