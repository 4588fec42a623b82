"""Metrics and checks from hand-made trajectories, and the progress bar."""

import io

import numpy as np
import pytest

from fpga_robotics.checks.summary import (
    compute_metrics,
    evaluate_checks,
    format_summary,
    rounded,
    verdict,
)
from fpga_robotics.cli.run import Progress, write_json_atomic

PERIOD = 0.1


def trajectory(found, dist, in_view=None, x=None):
    n = len(found)
    return {
        "t": np.arange(n) * PERIOD,
        "x": np.zeros(n) if x is None else np.asarray(x, float),
        "y": np.zeros(n),
        "driven_x": np.zeros(n) if x is None else np.asarray(x, float),
        "driven_y": np.zeros(n),
        "found": np.asarray(found, bool),
        "target_distance": np.asarray(dist, float),
        "target_in_view": np.ones(n, bool) if in_view is None else np.asarray(in_view, bool),
    }


def test_distances_fractions_and_path():
    tr = trajectory(
        [0, 1, 1, 0], [2.0, 1.0, np.nan, 3.0], in_view=[1, 1, 0, 0], x=[0.0, 0.3, 0.7, 0.7]
    )
    m = compute_metrics(tr, [], {"person": 1, "wall": 0}, PERIOD)
    assert m["min_distance_m"] == 1.0 and m["mean_distance_m"] == 2.0  # NaN ignored
    assert m["target_in_view_fraction"] == 0.5 and m["found_fraction"] == 0.5
    assert m["acquired_at_s"] == pytest.approx(0.1)
    assert m["found_after_acquisition_fraction"] == pytest.approx(2 / 3, abs=1e-4)
    assert m["path_length_m"] == pytest.approx(0.7)
    assert m["collisions"] == {"person": 1, "wall": 0}


def test_checks_judge_the_unrounded_metrics():
    # In view in 1 frame of 20004 (0.005%): 0.0 to the summary's 4 decimals, yet it meets
    # a limit of 0.001%, and it was in view, if never found.
    n = 20004
    glimpse = compute_metrics(
        trajectory([0] * n, [2.0] * n, in_view=[1] + [0] * (n - 1)), [], {}, PERIOD
    )
    assert glimpse["target_in_view_fraction"] == 1 / n
    assert rounded(glimpse)["target_in_view_fraction"] == 0.0
    in_view, acquired = evaluate_checks(
        {"target_in_view_min_fraction": 0.00001, "acquired_within_s": 1.0}, glimpse
    )
    assert in_view["status"] == "pass" and in_view["value"] == 1 / n
    assert in_view["text"] == "target in view 0.005% of frames (limit >= 0.001%)"
    assert acquired["text"] == "the target was never found (limit 1.0 s)"
    # In view in 22499 frames of 25000 (89.996%): 0.9 to 4 decimals, yet short of 90%.
    n = 25000
    short = compute_metrics(
        trajectory([1] * n, [2.0] * n, in_view=[1] * 22499 + [0] * 2501), [], {}, PERIOD
    )
    assert rounded(short)["target_in_view_fraction"] == 0.9
    (c,) = evaluate_checks({"target_in_view_min_fraction": 0.9}, short)
    assert c["status"] == "fail" and c["text"] == (
        "target in view 89.996% of frames (limit >= 90%)"
    )
    # A distance 0.04 mm short of its limit reads as short of it.
    close = compute_metrics(trajectory([1, 1], [0.59996, 1.0]), [], {}, PERIOD)
    (c,) = evaluate_checks({"min_distance_min_m": 0.6}, close)
    assert c["status"] == "fail" and c["text"] == "min distance 0.59996 m (limit >= 0.6 m)"
    # Found in frame 3 at 0.1 s a frame: 3 * 0.1 = 0.30000000000000004 in float arithmetic,
    # the time of the frame 0.3 s, at the microsecond the events are stamped with.
    third = compute_metrics(trajectory([0, 0, 0, 1], [1.0] * 4), [], {}, PERIOD)
    assert third["acquired_at_s"] == 0.3
    (c,) = evaluate_checks({"acquired_within_s": 0.3}, third)
    assert c["status"] == "pass" and c["text"] == "target first found at 0.30 s (limit 0.3 s)"


def test_no_target_at_all():
    m = compute_metrics(trajectory([0, 0], [np.nan, np.nan]), [], {}, PERIOD)
    assert m["min_distance_m"] is None and m["acquired_at_s"] is None
    checks = evaluate_checks({"acquired_within_s": 1.0, "mean_distance_max_m": 2.0}, m)
    assert [c["passed"] for c in checks] == [False, False]
    assert "never found" in checks[0]["text"]


def summary_of(m, checks, **extra):
    return {
        "scenario": "x",
        "backend": "model",
        "resolution": "160x120",
        "seed": 0,
        "frames": 2,
        "sim_time_s": 0.2,
        "wall_time_s": 0.01,
        "ms_per_frame": 5.0,
        "realtime_factor": 20.0,
        **m,
        "checks": checks,
        "verdict": verdict(checks),
        **extra,
    }


def test_a_run_without_a_target_person_says_so():
    m = compute_metrics(trajectory([0, 0], [np.nan, np.nan]), [], {"person": 0}, PERIOD)
    checks = evaluate_checks({"mean_distance_max_m": 3.5, "min_distance_min_m": 0.6}, m)
    assert [c["passed"] for c in checks] == [False, False]
    assert [c["value"] for c in checks] == [None, None]
    for c in checks:
        assert "None" not in c["text"]
        assert c["text"].startswith("no target person: no distance to compare")
    text = format_summary(summary_of(m, checks))
    assert "None" not in text
    assert "  target: none in the scenario (the design reported found in 0% of frames" in text
    assert "  distance: n/a (no target person)" in text
    assert (
        "[FAIL] mean_distance_max_m: no target person: no distance to compare (limit <= "
        "3.5 m)" in text
    )


def test_a_run_without_a_target_person_or_a_found_output_says_so_plainly():
    # A design of one's own without a camera (`fpga-robotics new`'s): nothing to report found.
    absent = ("found", "proximity", "centroid_x", "centroid_leds")
    m = compute_metrics(trajectory([0, 0], [np.nan, np.nan]), [], {}, PERIOD, absent=absent)
    text = format_summary(summary_of(m, [], absent_outputs=list(absent)))
    assert "  target: none in the scenario, and no tracker `found` output\n" in text
    assert "n/a" not in text.split("  target:")[1].split("\n")[0]


def test_a_run_too_fast_to_time_still_prints():
    m = compute_metrics(trajectory([1, 1], [1.0, 1.0]), [], {}, PERIOD)
    text = format_summary(summary_of(m, [], wall_time_s=0.0, realtime_factor=None))
    assert "0.2 s simulated in 0.00 s (5.00 ms/frame, n/a real time)" in text


def events(*items):
    return [(round(t / PERIOD), t, text) for t, text in items]


def test_loss_episodes_and_reacquisition():
    tr = trajectory([1] * 100, [1.0] * 100)
    ev = events(
        (0.0, "target found"),
        (2.0, "target lost"),
        (3.5, "search started"),
        (4.0, "target found"),
        (6.0, "target lost"),
        (6.5, "target found"),
    )
    m = compute_metrics(tr, ev, {}, PERIOD)
    assert m["losses"] == 2 and m["searched_losses"] == 1 and m["searches"] == 1
    assert m["reacquire_times_s"] == [2.0, 0.5] and m["unrecovered_losses_s"] == []
    (c,) = evaluate_checks({"reacquired_within_s": 3.0}, m)
    assert c["passed"] and c["value"] == 2.0
    (c,) = evaluate_checks({"reacquired_within_s": 1.5}, m)
    assert not c["passed"]


def test_reacquisition_needs_a_search_that_ended():
    tr = trajectory([1] * 100, [1.0] * 100)  # 10 s
    short = compute_metrics(
        tr, events((0.0, "target found"), (2.0, "target lost"), (2.2, "target found")), {}, PERIOD
    )
    (c,) = evaluate_checks({"reacquired_within_s": 5.0}, short)
    assert not c["passed"] and "never lost long enough" in c["text"]
    open_end = compute_metrics(
        tr, events((0.0, "target found"), (8.0, "target lost"), (9.5, "search started")), {}, PERIOD
    )
    assert open_end["unrecovered_losses_s"] == [2.0]  # run ends at 10.0 s
    # Lost 2 s before the end, within a 5 s limit: the run was cut short, nothing to judge.
    (c,) = evaluate_checks({"reacquired_within_s": 5.0}, open_end)
    assert c["status"] == "n/a" and c["reason"] == (
        "the run ended 2.00 s after the target was lost, the design still searching, within "
        "the 5.0 s limit: no re-acquisition to judge"
    )
    (c,) = evaluate_checks({"reacquired_within_s": 1.0}, open_end)
    assert c["status"] == "fail" and c["text"] == (
        "target lost and not found again for 2.00 s (limit 1.0 s)"
    )
    # A search that ended (found again 1.5 s after the loss) is judged; a younger open one
    # after it does not fail the run.
    judged = compute_metrics(
        tr,
        events(
            (0.0, "target found"),
            (2.0, "target lost"),
            (3.0, "search started"),
            (3.5, "target found"),
            (8.0, "target lost"),
            (9.5, "search started"),
        ),
        {},
        PERIOD,
    )
    (c,) = evaluate_checks({"reacquired_within_s": 2.5}, judged)
    assert c["status"] == "pass" and c["value"] == 1.5
    (c,) = evaluate_checks({"reacquired_within_s": 1.8}, judged)
    assert c["status"] == "fail" and "not found again for 2.00 s" in c["text"]


def test_a_loss_longer_than_the_limit_fails_though_the_design_never_searched():
    """A design that never searches (lost_frames beyond the loss) and loses the target for
    longer than the limit fails: the loss is what is judged, not the search."""
    tr = trajectory([1] * 100, [1.0] * 100)  # 10 s
    hidden = compute_metrics(tr, events((0.0, "target found"), (1.2, "target lost")), {}, PERIOD)
    assert hidden["searched_losses"] == 0 and hidden["unrecovered_losses_s"] == [8.8]
    (c,) = evaluate_checks({"reacquired_within_s": 4.0}, hidden)
    assert c["status"] == "fail" and c["text"] == (
        "target lost and not found again for 8.80 s (limit 4.0 s)"
    )
    came_back = compute_metrics(
        tr, events((0.0, "target found"), (1.0, "target lost"), (6.0, "target found")), {}, PERIOD
    )
    (c,) = evaluate_checks({"reacquired_within_s": 4.0}, came_back)
    assert c["status"] == "fail" and c["value"] == 5.0
    # Within the limit and never searched: nothing to judge, as before.
    (c,) = evaluate_checks({"reacquired_within_s": 6.0}, came_back)
    assert c["status"] == "n/a"
    assert c["reason"] == "the target was never lost long enough for the design to search"


def test_reacquisition_says_why_there_was_no_loss():
    tr = trajectory([0] * 30 + [1] * 70, [1.0] * 100)
    # Found after a search from the start (a robot facing away): searched, never lost.
    m = compute_metrics(tr, events((1.5, "search started"), (3.0, "target found")), {}, PERIOD)
    assert m["searches"] == 1 and m["losses"] == 0
    (c,) = evaluate_checks({"reacquired_within_s": 4.0}, m)
    assert (c["status"], c["reason"]) == ("n/a", "the target was never lost")
    never = compute_metrics(trajectory([0] * 100, [1.0] * 100), [], {}, PERIOD)
    (c,) = evaluate_checks({"reacquired_within_s": 4.0}, never)
    assert (c["status"], c["reason"]) == ("n/a", "the target was never found, so never lost")


def test_each_check_compares_with_its_limit():
    m = compute_metrics(
        trajectory([1, 1, 1, 1], [1.0, 0.8, 0.6, 1.4], in_view=[1, 1, 1, 0]),
        [],
        {"person": 0, "wall": 2, "furniture": 0},
        PERIOD,
    )
    limits = {
        "acquired_within_s": 0.0,
        "mean_distance_max_m": 0.9,  # mean 0.95: fails
        "min_distance_min_m": 0.6,  # min 0.6: passes (inclusive)
        "max_person_collisions": 0,
        "max_wall_collisions": 1,  # 2: fails
        "max_furniture_collisions": 0,
        "target_in_view_min_fraction": 0.75,
        "found_min_fraction": 1.0,
    }
    checks = evaluate_checks(limits, m)
    assert [c["name"] for c in checks] == list(limits)
    assert {c["name"]: c["passed"] for c in checks} == {
        "acquired_within_s": True,
        "mean_distance_max_m": False,
        "min_distance_min_m": True,
        "max_person_collisions": True,
        "max_wall_collisions": False,
        "max_furniture_collisions": True,
        "target_in_view_min_fraction": True,
        "found_min_fraction": True,
    }
    assert verdict(checks) == "fail" and verdict([c for c in checks if c["passed"]]) == "pass"
    assert verdict([]) == "pass"


def test_human_summary_mentions_failures():
    m = compute_metrics(trajectory([1, 1], [1.0, 1.0]), [], {"person": 1}, PERIOD)
    checks = evaluate_checks({"max_person_collisions": 0}, m)
    s = {
        "scenario": "x",
        "backend": "model",
        "resolution": "160x120",
        "seed": 0,
        "frames": 2,
        "sim_time_s": 0.2,
        "wall_time_s": 0.01,
        "ms_per_frame": 5.0,
        "realtime_factor": 20.0,
        **m,
        "checks": checks,
        "verdict": verdict(checks),
    }
    text = format_summary(s)
    assert "[FAIL] max_person_collisions: 1 collision(s) with person" in text
    assert text.endswith("verdict: FAIL")


class FakeTTY(io.StringIO):
    def isatty(self):
        return True


def test_progress_redraws_in_place_on_a_terminal_and_prints_lines_otherwise():
    tty = FakeTTY()
    p = Progress("run", stream=tty)
    for k in range(1, 11):
        p._last_draw = 0.0  # do not throttle in the test
        p(k, 10)
    p.finish()
    out = tty.getvalue()
    assert out.count("\r") == 10 and "10/10 frames" in out and out.endswith("\n")
    plain = io.StringIO()
    p = Progress("run", stream=plain)
    for k in range(1, 101):
        p(k, 100)
    lines = plain.getvalue().splitlines()
    assert "\r" not in plain.getvalue()
    assert lines[0].startswith("run: 0%") and lines[-1] == "run: 100% (100/100 frames)"
    assert len(lines) == 6


def test_write_json_atomic_leaves_nothing_behind_on_failure(tmp_path):
    path = tmp_path / "s.json"
    write_json_atomic(path, {"a": 1})
    with pytest.raises(TypeError):
        write_json_atomic(path, {"a": object()})
    assert path.read_text().strip().replace(" ", "").replace("\n", "") == '{"a":1}'
    assert list(tmp_path.iterdir()) == [path]


def test_the_target_line_never_rounds_onto_0_or_100_percent():
    m = compute_metrics(trajectory([1, 1], [1.0, 1.0]), [], {}, PERIOD)
    # 299 frames of 300 in view, 1 of 300 found: neither is all, nor none.
    m = {**m, "target_in_view_fraction": 299 / 300, "found_fraction": 1 / 300}
    text = format_summary(summary_of(m, []))
    assert ", in view 99.7%, found 0.3%," in text
    m = {**m, "target_in_view_fraction": 1.0, "found_fraction": 0.5}
    assert ", in view 100%, found 50%," in format_summary(summary_of(m, []))
