"""The registry of checks: every shipped check judged and not judged (n/a, with its reason) on
hand-made metrics; the verdict with n/a checks; n/a in the printed summary, the summary JSON,
a campaign row, the campaign report and report.html; a silent sensor; and a check declared
through the registry alone showing up in a run, a campaign row and the docs' table check."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

from fpga_robotics.checks.check import Check
from fpga_robotics.checks.registry import (
    CHECKS,
    check_names,
    evaluate_checks,
    register_check,
    unregister_check,
    verdict,
)
from fpga_robotics.checks.sensor_metrics import measurement_metrics
from fpga_robotics.checks.shipped import SHIPPED_CHECKS
from fpga_robotics.checks.summary import format_summary
from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.run import main as run_main
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import ScenarioError, load_scenario
from fpga_robotics.sweep.campaign import RunSpec
from fpga_robotics.sweep.report import format_report, write_html
from fpga_robotics.sweep.results import load_rows, make_row, write_tables

DOCS = Path(__file__).resolve().parent.parent / "docs" / "running.md"
SMALL = ['camera.resolution="80x60"', "sim.duration=1"]

#: A run every shipped check can judge: the metrics each reads, made up by hand.
JUDGEABLE = {
    "acquired_at_s": 0.5,
    "target_in_view_fraction": 0.95,
    "found_after_acquisition_fraction": 0.92,
    "mean_distance_m": 2.0,
    "min_distance_m": 1.0,
    "collisions": {"person": 1, "wall": 2, "furniture": 3},
    "robot_at_fault_collisions": 1,
    "tip_overs": 1,
    "tipped_over_at_s": 3.17,
    "oscillation_hz": 0.5,
    "off_target_fraction": 0.05,
    "mean_centroid_error_px": 1.5,
    "led_wrong_side_fraction": 0.1,
    "led_misplaced_fraction": 0.1,
    "peak_wheel_command_dps": 400,
    "search_travel_m": 0.05,
    "heading_overshoot_deg": 3.0,
    "mean_aim_error_deg": 4.0,
    "searched_losses": 1,
    "searched_reacquisitions": 1,
    "reacquire_times_s": [2.0],
    "unrecovered_losses_s": [],
    "lateral_error_max_m": 0.03,
    "lateral_error_mean_m": 0.01,
    "laps": 2,
    "off_line_s": 0.5,
    "obstacle_removed_at_s": 12.0,
    "resumed_after_s": 2.4,
    "run_after_removal_s": 18.0,
    "measured_frames": {"front": 30},
    "measured_frames_min": 30,
    "silent_sensors": [],
    "sensor_kinds": {"front": "ultrasound"},
    "absent_outputs": [],
    "approach_speed_violation_fraction": 0.1,
    "reverse_when_far_fraction": 0.1,
    "stop_overshoot_m": 0.05,
    "stop_distance_m": 1.2,
    "stop_closest_m": 1.1,
    "turn_law_violation_fraction": 0.1,
    "search_law_violation_fraction": 0.1,
    "envelope_reason": None,
    "camera_target_in_view_fraction": 0.9,
    "camera_target_centred_fraction": 0.8,
}

_IN_VIEW = "the target was never found"
_NO_LINE = "not measured: the run has no floor line or no line sensors"
#: Checks with a precondition: name -> (a limit the JUDGEABLE run passes, one it fails, the
#: metrics that leave the check nothing to judge, the reason it then gives).
JUDGED_IF = {
    "max_oscillation_hz": (0.5, 0.4, {"oscillation_hz": None}, "the target was never found"),
    "max_off_target_fraction": (
        0.05,
        0.04,
        {"off_target_fraction": None},
        "the design never reported the target found with its centre in view, nor with it out of view",
    ),
    "mean_centroid_error_max_px": (
        1.5,
        1.4,
        {"mean_centroid_error_px": None},
        "the design never reported the target found with it in view",
    ),
    "max_led_wrong_side_fraction": (
        0.1,
        0.09,
        {"led_wrong_side_fraction": None},
        "the target was never found to one side or at the centre",
    ),
    "max_led_misplaced_fraction": (
        0.1,
        0.09,
        {"led_misplaced_fraction": None},
        "the target was never found inside the window",
    ),
    "max_wheel_command_dps": (400, 399, {"peak_wheel_command_dps": None}, "no wheel command"),
    "max_search_travel_m": (0.05, 0.04, {"search_travel_m": None}, "the design never searched"),
    "max_heading_overshoot_deg": (
        3.0,
        2.9,
        {"heading_overshoot_deg": None},
        "the target's centre was never in view",
    ),
    "max_mean_aim_error_deg": (
        4.0,
        3.9,
        {"mean_aim_error_deg": None},
        "no target person: no aim to judge",
    ),
    "reacquired_within_s": (
        2.0,
        1.9,
        {"searched_losses": 0, "searched_reacquisitions": 0, "reacquire_times_s": [0.3]},
        "the target was never lost long enough for the design to search",
    ),
    "max_lateral_error_m": (0.03, 0.02, {"lateral_error_max_m": None}, _NO_LINE),
    "min_laps": (2, 3, {"laps": None}, _NO_LINE),
    "max_off_line_s": (0.5, 0.4, {"off_line_s": None}, _NO_LINE),
    "resumes_within_s": (
        2.4,
        2.3,
        {"obstacle_removed_at_s": None, "resumed_after_s": None},
        ("no furniture was removed during the run (room.furniture.present_until)"),
    ),
    "min_measured_frames": (
        30,
        31,
        {
            "measured_frames": {},
            "measured_frames_min": None,
            "silent_sensors": [],
            "sensor_kinds": {},
        },
        "the robot has no sensor that measures ([[robot.sensors]])",
    ),
    "max_approach_speed_violation_fraction": (
        0.1,
        0.09,
        {"approach_speed_violation_fraction": None},
        "the target was never found centred and wholly in the window",
    ),
    "max_reverse_when_far_fraction": (
        0.1,
        0.09,
        {"reverse_when_far_fraction": None},
        "the target was never found beyond the reversing distance",
    ),
    "max_stop_overshoot_m": (
        0.05,
        0.04,
        {"stop_overshoot_m": None, "stop_reason": "the robot never came near the stop distance"},
        "the robot never came near the stop distance",
    ),
    "max_turn_law_violation_fraction": (
        0.1,
        0.09,
        {"turn_law_violation_fraction": None},
        "the target was never found wholly in the window",
    ),
    "max_search_law_violation_fraction": (
        0.1,
        0.09,
        {"search_law_violation_fraction": None},
        "the target was never lost",
    ),
    "camera_target_in_view_min_fraction": (
        0.9,
        0.91,
        {"camera_target_in_view_fraction": None},
        "no further camera has a target",
    ),
    "camera_target_centred_min_fraction": (
        0.8,
        0.81,
        {"camera_target_centred_fraction": None},
        "no further camera has a target",
    ),
}
#: Checks that always judge: name -> (a limit the JUDGEABLE run passes, one it fails).
ALWAYS_JUDGED = {
    "acquired_within_s": (0.5, 0.4),
    "found_min_fraction": (0.92, 0.93),
    "mean_distance_max_m": (2.0, 1.9),
    "min_distance_min_m": (1.0, 1.1),
    "max_person_collisions": (1, 0),
    "max_wall_collisions": (2, 1),
    "max_furniture_collisions": (3, 2),
    "max_robot_at_fault_collisions": (1, 0),
    "max_tip_overs": (1, 0),
    "target_in_view_min_fraction": (0.95, 0.96),
}
#: Metrics that leave every check with a precondition nothing to judge.
NOTHING_TO_JUDGE = {**JUDGEABLE}
for _limits in JUDGED_IF.values():
    NOTHING_TO_JUDGE.update(_limits[2])


def _one(name, limit, metrics):
    (c,) = evaluate_checks({name: limit}, metrics)
    return c


def test_every_shipped_check_is_registered_once_and_covered_here():
    names = [c.name for c in SHIPPED_CHECKS]
    assert len(names) == len(set(names))
    assert names == check_names()[: len(names)]
    assert set(names) == set(JUDGED_IF) | set(ALWAYS_JUDGED)
    assert not set(JUDGED_IF) & set(ALWAYS_JUDGED)
    for c in SHIPPED_CHECKS:
        assert (c.precondition is not None or bool(c.sensors)) == (c.name in JUDGED_IF), c.name


@pytest.mark.parametrize("name", sorted(JUDGED_IF))
def test_a_check_judges_when_its_precondition_holds_and_is_na_when_not(name):
    passing, failing, nothing, reason = JUDGED_IF[name]
    ok = _one(name, passing, JUDGEABLE)
    assert (ok["status"], ok["passed"], ok["reason"]) == ("pass", True, None), ok
    bad = _one(name, failing, JUDGEABLE)
    assert (bad["status"], bad["passed"]) == ("fail", False), bad
    na = _one(name, passing, {**JUDGEABLE, **nothing})
    assert (na["status"], na["passed"], na["value"]) == ("n/a", None, None)
    assert na["reason"] == na["text"] == reason
    assert verdict([na]) == "n/a" and verdict([na, ok]) == "pass" and verdict([na, bad]) == "fail"


@pytest.mark.parametrize("name", sorted(ALWAYS_JUDGED))
def test_a_check_without_precondition_always_judges(name):
    passing, failing = ALWAYS_JUDGED[name]
    assert _one(name, passing, JUDGEABLE)["status"] == "pass"
    assert _one(name, failing, JUDGEABLE)["status"] == "fail"
    assert _one(name, passing, NOTHING_TO_JUDGE)["status"] in ("pass", "fail")


@pytest.mark.parametrize("check", [c for c in SHIPPED_CHECKS if c.outputs], ids=lambda c: c.name)
def test_a_design_lacking_an_output_makes_its_checks_na(check):
    limit = (JUDGED_IF.get(check.name) or ALWAYS_JUDGED.get(check.name))[0]
    c = _one(check.name, limit, {**JUDGEABLE, "absent_outputs": [check.outputs[-1]]})
    assert c["status"] == "n/a"
    assert c["reason"] == f"not measured: the design has no `{check.outputs[-1]}` output"


def test_failures_keep_their_reasons_apart_from_na():
    # Found never, though in view: acquisition fails (not n/a); a search still open at the
    # end, 0.5 s after the loss, is younger than the 4 s limit: nothing to judge.
    m = {
        **JUDGEABLE,
        "acquired_at_s": None,
        "searched_reacquisitions": 0,
        "reacquire_times_s": [],
        "unrecovered_losses_s": [0.5],
    }
    c = _one("acquired_within_s", 1.0, m)
    assert c["status"] == "fail" and c["text"] == _IN_VIEW + " (limit 1.0 s)"
    # Never in view either: the design never turned to the target, which is its doing, so
    # a failure too (a design that never searches passed a following scenario as n/a).
    never = {**m, "target_in_view_fraction": 0}
    c = _one("acquired_within_s", 1.0, never)
    assert c["status"] == "fail"
    assert c["text"] == "the target was never found (never in the camera's view) (limit 1.0 s)"
    c = _one("found_min_fraction", 0.9, {**never, "found_after_acquisition_fraction": 0.0})
    assert c["status"] == "fail"
    assert c["text"] == (
        "the target was never found (never in the camera's view) (limit >= 90% of the frames "
        "after it is)"
    )
    c = _one("reacquired_within_s", 4.0, m)
    assert c["status"] == "n/a" and c["reason"] == (
        "the run ended 0.50 s after the target was lost, the design still searching, within "
        "the 4.0 s limit: no re-acquisition to judge"
    )
    c = _one("reacquired_within_s", 0.4, m)
    assert c["status"] == "fail" and c["text"] == (
        "target lost and not found again for 0.50 s (limit 0.4 s)"
    )
    # The furniture left but the robot never drove towards the target: a failure.
    c = _one("resumes_within_s", 3.0, {**JUDGEABLE, "resumed_after_s": None})
    assert c["status"] == "fail" and "never drove 0.2 m towards the target" in c["text"]
    # A silent sensor fails min_measured_frames, naming it.
    silent = {
        **JUDGEABLE,
        "measured_frames": {"front": 0},
        "measured_frames_min": 0,
        "silent_sensors": ["front"],
    }
    c = _one("min_measured_frames", 1, silent)
    assert c["status"] == "fail" and c["text"].startswith("no measurement at all from front")


def test_the_verdict():
    ok = {"passed": True}
    fail = {"passed": False}
    na = {"passed": None}
    assert verdict([]) == "pass"  # no check set: nothing failed
    assert verdict([ok, na]) == "pass"
    assert verdict([na, na]) == "n/a"  # set checks, none could judge: no pass
    assert verdict([ok, na, fail]) == "fail"


def test_measurement_counts_by_hand():
    nan = np.nan
    columns = {
        "front.echo_m": np.array([nan, nan, 0.5, 0.6]),
        "front.range_m": np.array([nan, nan, nan, 0.6]),
        "bump.pressed": np.array([0.0, 0.0, 1.0, 0.0]),
    }
    sensors = [("front", "ultrasound"), ("bump", "bumper"), ("rear", "ultrasound")]
    # Three frames done: front measured in frame 2 only; the fourth row is not counted.
    m = measurement_metrics(columns, sensors, 3)
    assert m["measured_frames"] == {"front": 1, "bump": 3, "rear": 0}
    assert m["measured_frames_min"] == 0 and m["silent_sensors"] == ["rear"]
    assert m["sensor_kinds"] == dict(sensors)
    none = measurement_metrics({}, [], 3)
    assert none["measured_frames_min"] is None and none["silent_sensors"] == []


@pytest.fixture
def ultrasound_check():
    """A user's check that reads the ultrasound: n/a when no ultrasound measured."""
    check = register_check(
        name="min_distance_ranged_m",
        metric="min_distance_m",
        compare="min",
        meaning="closest robot-to-target distance, on runs in which the ultrasound ranged",
        message=lambda v, limit, m: f"min distance {v} m (limit >= {limit} m)",
        limits=(0, 1000, "m"),
        sensors=("ultrasound",),
    )
    yield check
    unregister_check(check.name)


def test_a_check_reading_a_silent_sensor_is_na(ultrasound_check):
    name = ultrasound_check.name
    assert _one(name, 0.5, JUDGEABLE)["status"] == "pass"
    silent = {**JUDGEABLE, "measured_frames": {"front": 0}, "silent_sensors": ["front"]}
    c = _one(name, 0.5, silent)
    assert c["status"] == "n/a" and c["reason"] == "no ultrasound measurement arrived"
    c = _one(name, 0.5, {**JUDGEABLE, "sensor_kinds": {"front": "bumper"}})
    assert c["status"] == "n/a" and c["reason"] == "the robot has no ultrasound sensor"


def _summary(m, checks, **extra):
    return {
        "scenario": "x",
        "backend": "model",
        "resolution": "40x24",
        "seed": 0,
        "frames": 30,
        "sim_time_s": 1.0,
        "wall_time_s": 0.5,
        "ms_per_frame": 16.0,
        "realtime_factor": 2.0,
        "found_fraction": 1.0,
        "searches": 0,
        "path_length_m": 0.5,
        **m,
        "checks": checks,
        "verdict": verdict(checks),
        **extra,
    }


def test_the_printed_summary_shows_na_the_warning_and_the_na_verdict(ultrasound_check):
    silent = {
        **JUDGEABLE,
        "measured_frames": {"front": 0},
        "measured_frames_min": 0,
        "silent_sensors": ["front"],
    }
    checks = evaluate_checks(
        {ultrasound_check.name: 0.5, "max_search_travel_m": 0.1},
        {**silent, "search_travel_m": None},
    )
    text = format_summary(_summary(silent, checks))
    assert "  warning: no measurement at all from sensor(s) front" in text
    assert f"  [n/a] {ultrasound_check.name}: no ultrasound measurement arrived" in text
    assert "  [n/a] max_search_travel_m: the design never searched" in text
    assert text.endswith("verdict: N/A (no check could judge this run)")
    assert "verdict: PASS" not in text
    # With a requirement of measurements the same run fails.
    checks = evaluate_checks({ultrasound_check.name: 0.5, "min_measured_frames": 1}, silent)
    text = format_summary(_summary(silent, checks))
    assert "[FAIL] min_measured_frames: no measurement at all from front" in text
    assert text.endswith("verdict: FAIL")


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        run_cli(run_main, argv, prog="fpga_robotics.run")
    out, err = capsys.readouterr()
    return info.value.code, out, err


def test_a_run_no_check_could_judge_is_na_in_the_json_and_exits_1(tmp_path, capsys):
    path = tmp_path / "s.json"
    code, out, err = _cli(
        [
            "--backend",
            "model",
            "--resolution",
            "80x60",
            "--duration",
            "1",
            "--rerun",
            "off",
            "--quiet",
            "--summary",
            str(path),
            "--set",
            "checks={max_search_travel_m = 0.1}",
        ],
        capsys,
    )
    s = json.loads(path.read_text())
    assert s["searches"] == 0  # the design found the person at once and never searched
    (c,) = s["checks"]
    assert (c["name"], c["status"], c["passed"], c["reason"]) == (
        "max_search_travel_m",
        "n/a",
        None,
        "the design never searched",
    )
    assert s["verdict"] == "n/a" and code == 1, err
    assert "[n/a] max_search_travel_m: the design never searched" in out
    assert "verdict: N/A (no check could judge this run)" in out


def test_lost_target_on_a_gopigo3_passes_on_the_checks_that_can_judge():
    # The GoPiGo3 turns fast enough to keep the person in view: it never loses them.
    r = run_scenario(load_scenario("lost_target", ['robot.model="gopigo3"']), backend="model")
    by = {c["name"]: c for c in r.summary["checks"]}
    assert r.summary["losses"] == 0
    assert by["reacquired_within_s"]["status"] == "n/a"
    assert by["reacquired_within_s"]["reason"] == "the target was never lost"
    assert all(c["status"] == "pass" for n, c in by.items() if n != "reacquired_within_s")
    assert r.summary["verdict"] == "pass"


def _row(summary, seed, overrides=(("design.diff_min", 6),)):
    spec = RunSpec(scenario="follow_person", seed=seed, overrides=overrides, backend="model")
    outcome = {"status": summary["verdict"], "summary": summary, "wall_s": 1.0}
    return make_row(spec, f"run{seed}", "follow_person", outcome)


def _campaign_rows():
    m = {**JUDGEABLE, "search_travel_m": None, "collisions": {"person": 1}}
    failing = evaluate_checks(
        {"max_person_collisions": 0, "max_search_travel_m": 0.1, "acquired_within_s": 1.0}, m
    )
    unjudged = evaluate_checks({"max_search_travel_m": 0.1}, m)
    passing = evaluate_checks({"acquired_within_s": 1.0}, m)
    return [
        _row(_summary(m, failing), 0),
        _row(_summary(m, unjudged), 1),
        _row(_summary(m, passing), 2),
    ]


def test_campaign_rows_keep_failed_and_na_checks_apart(tmp_path):
    failing, unjudged, passing = _campaign_rows()
    assert failing["status"] == "fail"
    assert failing["failed_checks"] == "max_person_collisions"  # the n/a one is not a failure
    assert failing["na_checks"] == "max_search_travel_m"
    assert failing["check_max_search_travel_m"] is None
    assert failing["check_max_person_collisions"] is False
    assert failing["message"].startswith("max_person_collisions: 1 collision(s) with person")
    assert unjudged["status"] == "n/a" and unjudged["failed_checks"] == ""
    assert unjudged["na_checks"] == "max_search_travel_m"
    assert unjudged["message"] == "max_search_travel_m: the design never searched"
    assert (passing["status"], passing["failed_checks"], passing["na_checks"]) == ("pass", "", "")
    # The tables keep the columns (a Parquet table read back, no journal).
    write_tables(tmp_path, [failing, unjudged, passing])
    back = load_rows(tmp_path)
    assert [r["na_checks"] for r in back] == ["max_search_travel_m"] * 2 + [""]
    assert [r["status"] for r in back] == ["fail", "n/a", "pass"]


def test_the_campaign_report_lists_na_checks_with_their_reasons(tmp_path):
    rows = _campaign_rows()
    text = format_report(rows, ["design.diff_min"])
    assert text.splitlines()[0] == (
        "3 runs: 1 pass, 1 fail, 1 n/a, 0 error, 0 timeout (pass rate 33%)"
    )
    assert "  max_person_collisions: 1 run(s)" in text and "  n/a: 1 run(s)" in text
    assert (
        "  max_search_travel_m: 2 run(s): the design never searched"
        in text.split("checks that could not judge (n/a; not counted as pass or fail):")[1]
    )
    path = tmp_path / "report.html"
    write_html(path, rows, ["design.diff_min"], {"name": "t"})
    page = path.read_text()
    na = page.split("<h2>Checks that could not judge (n/a)</h2>")[1]
    assert "<h3>max_search_travel_m (2 run(s))</h3>" in na
    assert na.count("<td>the design never searched</td>") == 2
    assert "max_person_collisions" not in na


def documented_checks(text):
    """The check names in the first column of docs/running.md's table of checks."""
    table = text.split("### Checks", 1)[1].split("\n\n", 2)[1]
    names = []
    for line in table.splitlines()[2:]:
        first = line.split("|")[1]
        names += re.findall(r"`([a-z_]+)(?: = [^`]*)?`", first)
    return names


def undocumented_checks(text):
    return [n for n in check_names() if n not in documented_checks(text)]


def test_the_docs_table_lists_exactly_the_registered_checks():
    documented = documented_checks(DOCS.read_text())
    assert len(documented) == len(set(documented))
    assert undocumented_checks(DOCS.read_text()) == []
    assert set(documented) == set(check_names())


@pytest.fixture
def path_check():
    """A check declared through the registry only."""
    check = register_check(
        Check(
            name="max_path_length_m",
            metric="path_length_m",
            compare="max",
            meaning="the robot drives at most this far",
            message=lambda v, limit, m: f"drove {v:.2f} m (limit <= {limit} m)",
            limits=(0, 1000, "m"),
            precondition=lambda m: "the robot never moved" if not m["path_length_m"] else None,
        )
    )
    yield check
    unregister_check(check.name)


def test_a_check_declared_through_the_registry_shows_everywhere(path_check):
    assert CHECKS["max_path_length_m"] == (
        float,
        (0, 1000, "m"),
        "the robot drives at most this far",
    )
    with pytest.raises(
        ScenarioError,
        match=r"checks.max_path_length_m must be a number in "
        r"0..1000 m, got -1",
    ):
        load_scenario("follow_person", [*SMALL, "checks.max_path_length_m=-1"])
    s = load_scenario("follow_person", [*SMALL, "checks={max_path_length_m = 100.0}"])
    r = run_scenario(s, backend="model")
    (c,) = r.summary["checks"]
    path = r.summary["path_length_m"]  # shown to 4 decimals; the check judged it unrounded
    assert path > 0 and (c["name"], c["status"]) == ("max_path_length_m", "pass")
    assert round(c["value"], 4) == path
    assert f"[ok] max_path_length_m: drove {c['value']:.2f} m (limit <= 100.0 m)" in format_summary(
        r.summary
    )
    # Its precondition: a robot that never moved gives it nothing to judge.
    assert _one("max_path_length_m", 1.0, {**r.summary, "path_length_m": 0.0})["reason"] == (
        "the robot never moved"
    )
    row = _row(r.summary, 0)
    assert row["check_max_path_length_m"] is True and row["status"] == "pass"
    # The docs' table of checks does not list it: the docs test names it.
    assert undocumented_checks(DOCS.read_text()) == ["max_path_length_m"]
    with pytest.raises(ValueError, match="already registered"):
        register_check(path_check)


def test_a_registered_check_reads_a_design_of_ones_own_outputs():
    # The metrics a check saw lacked extra_outputs: its value was None, the check failed.
    designs = Path(__file__).parent / "data" / "user_designs"
    check = register_check(
        Check(
            name="max_red_count",
            metric=lambda m: m["extra_outputs"]["red_count"]["max"],
            compare="max",
            meaning="the design counts at most this many red pixels in a frame",
            message=lambda v, limit, m: f"red count max {v} (limit <= {limit})",
            kind=int,
            limits=(0, 4800, ""),
            precondition=lambda m: None if "red_count" in m["extra_outputs"] else "no red_count",
        )
    )
    try:
        s = load_scenario(
            str(designs / "red_frames.toml"), ["sim.duration=0.5", "checks={max_red_count = 4800}"]
        )
        r = run_scenario(s, backend="cxxrtl")
        (c,) = r.summary["checks"]
        assert c["status"] == "pass"
        assert c["value"] == r.summary["extra_outputs"]["red_count"]["max"] > 0
        assert _one("max_red_count", 0, {**r.summary, "extra_outputs": {}})["reason"] == (
            "no red_count"
        )
    finally:
        unregister_check(check.name)


def test_the_loader_checks_the_new_key():
    with pytest.raises(ScenarioError, match=r"checks.min_measured_frames must be an integer"):
        load_scenario("follow_person", [*SMALL, "checks.min_measured_frames=1.5"])
    with pytest.raises(ScenarioError, match="max_path_length_m"):
        load_scenario("follow_person", [*SMALL, "checks.max_path_length_m=1"])


def test_a_declaration_is_checked():
    def make(**over):
        return Check(
            **{
                "name": "x_max",
                "metric": "x",
                "compare": "max",
                "meaning": "m",
                "message": str,
                **over,
            }
        )

    for bad, message in (
        ({"compare": "below"}, "compare must be one of"),
        ({"outputs": ("wheels",)}, "unknown design output"),
        ({"name": "not a name"}, "must be an identifier"),
        ({"kind": str}, "kind must be int or float"),
    ):
        with pytest.raises(ValueError, match=message):
            make(**bad)


def test_a_silent_ultrasound_warns_makes_its_checks_na_and_fails_min_measured_frames(
    ultrasound_check, capsys
):
    """A real-clock run too short for any echo (one frame, captured before the first TRIG
    pulse's echo ended): the HC-SR04 connector reports nothing."""
    from fpga_robotics.sim.backends import BackendError, available_backends

    if "cxxrtl" not in available_backends():
        pytest.skip("no C++ compiler here: no real-clock backend")
    s = load_scenario(
        "obstacle_between",
        ["sim.duration=0.02", f"checks={{min_measured_frames = 1, {ultrasound_check.name} = 0.5}}"],
    )
    try:
        r = run_scenario(s, backend="cxxrtl")
    except BackendError as exc:
        pytest.skip(f"cxxrtl cannot build here: {exc}")
    summary = r.summary
    assert summary["frames"] == 1
    assert summary["measured_frames"] == {"front": 0} and summary["silent_sensors"] == ["front"]
    by = {c["name"]: c for c in summary["checks"]}
    assert by["min_measured_frames"]["status"] == "fail"
    assert by[ultrasound_check.name]["reason"] == "no ultrasound measurement arrived"
    assert summary["verdict"] == "fail"
    text = format_summary(summary)
    assert "  warning: no measurement at all from sensor(s) front" in text
    # Without the requirement the silent run is not a pass either: no check could judge it.
    only = evaluate_checks({ultrasound_check.name: 0.5}, summary)
    assert verdict(only) == "n/a"
    assert format_summary({**summary, "checks": only, "verdict": verdict(only)}).endswith(
        "verdict: N/A (no check could judge this run)"
    )


@pytest.mark.parametrize(
    ("fraction", "shown"),
    [(0.9967, "99.7%"), (0.99996, "99.996%"), (1.0, "100%"), (0.004, "0.4%"), (0.5, "50%")],
)
def test_a_fraction_is_not_rounded_to_all_or_nothing(fraction, shown):
    """0.9967 of the frames is not "100%" (a limit of 100% fails it)."""
    c = _one("target_in_view_min_fraction", 1.0, {"target_in_view_fraction": fraction})
    assert f"target in view {shown} of frames" in c["text"]
    assert c["status"] == ("pass" if fraction == 1.0 else "fail")
