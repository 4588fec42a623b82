"""A pin-level run's stop budget: the robot judge's ``timeout`` counted in the design's own
watched output changes, not in seconds, so the verdict is the same on any machine.

``trig_storm.v`` drives at 200 DPS with its ultrasound trigger quiet, or, with the runtime
input ``storm`` set, toggling at every edge: each edge is a watched change where the loop
stops, like a mutant that breaks a trigger's counter."""

from pathlib import Path

import pytest

from fpga_robotics.mutation.forked_runs import _references, execute_forked, reference_share
from fpga_robotics.mutation.robot_judge import run_limits
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sweep import runner

STORM = Path(__file__).parent / "data" / "trig_storm" / "trig_storm.toml"

BACKENDS = ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)]


def _argv(backend, storm):
    return [
        "--scenario",
        str(STORM),
        "--seed",
        "0",
        "--backend",
        backend,
        "--runtime",
        f"storm={storm}",
    ]


def _edges():
    """The edges of the whole run: its duration at its clock."""
    sim = load_scenario(str(STORM)).sim
    return round(sim.duration * sim.clock_hz)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_design_s_stops_are_its_watched_changes(backend):
    quiet = runner.execute(_argv(backend, 0))
    storm = runner.execute(_argv(backend, 1))
    assert quiet["status"] == storm["status"] == "pass", (quiet["message"], storm["message"])
    assert quiet["design_stops"] == 0  # the trigger never moves
    assert storm["design_stops"] == _edges()  # it changes at every edge of the run
    # The budget goes with the run, not with the kept model: the next run without one ends.
    again = runner.execute(_argv(backend, 1))
    assert again["status"] == "pass" and again["design_stops"] == _edges()


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_run_over_its_budget_times_out_at_the_same_change_full_or_forked(backend):
    budget = 1000
    full = runner.execute(_argv(backend, 1), stop_limit=budget)
    assert full["status"] == "timeout"
    # Edge e changes the trigger (e = 1, 2, ...): change budget + 1 is at edge budget + 1.
    assert f"more than {budget} times" in full["message"]
    assert f"at edge {budget + 1}" in full["message"]
    assert full["design_stops"] == budget + 1
    _references.clear()
    shared = reference_share(_argv(backend, 0))
    assert shared["outcome"]["status"] == "pass"
    assert shared["outcome"]["design_stops"] == 0
    forked = execute_forked(_argv(backend, 1), _argv(backend, 0), shared=shared, stop_limit=budget)
    assert (forked["status"], forked["message"]) == (full["status"], full["message"])
    # Without a budget the forked run counts every change, as the full run does.
    whole = execute_forked(_argv(backend, 1), _argv(backend, 0), shared=shared)
    assert whole["status"] == "pass" and whole["design_stops"] == _edges()
    _references.clear()


def test_the_judge_s_limits_count_stops_for_pin_designs_only():
    # A hundred times the unmutated run's stops and a million more; seconds only for a hang.
    assert run_limits({"design_stops": 37, "wall_s": 2.0}) == (120.0, 1_003_700)
    assert run_limits({"design_stops": 0, "wall_s": 10.0}) == (300.0, 1_000_000)
    # A frame-level design: its frames' cycle watchdog bounds its work.
    assert run_limits({"design_stops": None, "wall_s": 1.0}) == (120.0, None)


def test_wall_stop_stops_twice_a_trigger_period():
    # docs/your_design.md: WallStop triggers every 20 ms (period_us) and the loop stops at
    # each TRIG rise and fall: 12 s / 20 ms * 2 = 1,200, so its mutants' budget is 1,120,000.
    scenario = Path(__file__).parent / "data" / "user_designs" / "wall_stop.toml"
    outcome = runner.execute(["--scenario", str(scenario), "--seed", "0"])
    assert outcome["status"] == "pass", outcome["message"]
    sim = load_scenario(str(scenario)).sim
    assert outcome["design_stops"] == round(sim.duration / 0.020) * 2 == 1200
    assert run_limits(outcome)[1] == 1_120_000
