"""The sensor designs' metrics against hand-computed values."""

import numpy as np
import pytest

from fpga_robotics.checks.registry import sensor_check
from fpga_robotics.checks.sensor_metrics import RESUME_CLOSING_M, obstacle_metrics


def _traj(t, robot_x, target_x, robot_y=None):
    """Rows at times ``t``: the robot and the target on the line y = 0 (the robot at
    ``robot_y`` off it when given)."""
    n = len(t)
    return {
        "t": np.asarray(t, float),
        "x": np.asarray(robot_x, float),
        "y": np.zeros(n) if robot_y is None else np.asarray(robot_y, float),
        "target_x": np.asarray(target_x, float),
        "target_y": np.zeros(n),
    }


REMOVED = [(3, 1.0, "furniture 'box' removed"), (0, 0.0, "target found")]


def test_resumed_after_is_the_first_row_the_robot_has_driven_the_margin_towards_the_target():
    # Removed at 1.0 s, the target standing at x = 3: the robot drives 0.1 m by 1.4 s (not
    # enough), 0.25 m by 1.6 s.
    t = [0.0, 0.5, 1.0, 1.2, 1.4, 1.6, 1.8]
    x = [0.5, 1.0, 1.0, 1.0, 1.1, 1.25, 1.5]
    m = obstacle_metrics(_traj(t, x, [3.0] * 7), REMOVED, 0.2)
    assert m["obstacle_removed_at_s"] == 1.0
    assert 0.1 < RESUME_CLOSING_M < 0.25
    assert m["resumed_after_s"] == pytest.approx(0.6)
    assert sensor_check("resumes_within_s", 1.0, m)[0] is True
    assert sensor_check("resumes_within_s", 0.5, m)[0] is False


def test_a_person_walking_up_to_a_robot_that_stays_put_is_not_a_resumption():
    # The robot stands at x = 1 while the person walks from 3 to 2: 1 m closer, robot 0 m.
    t = [1.0, 1.5, 2.0, 2.5, 3.0]
    m = obstacle_metrics(_traj(t, [1.0] * 5, [3.0, 2.75, 2.5, 2.25, 2.0]), REMOVED, 0.5)
    assert m["resumed_after_s"] is None
    ok, text = sensor_check("resumes_within_s", 1.5, m)
    assert ok is False and text.startswith("the robot never drove 0.2 m towards the target")
    # Following a person who walks away as fast: the distance stays 2 m, the robot drives
    # 0.25 m a row towards them: 0.25 >= 0.2 after the first step, at 1.5 s.
    walk = [1.0, 1.25, 1.5, 1.75, 2.0]
    m = obstacle_metrics(_traj(t, walk, [w + 2.0 for w in walk]), REMOVED, 0.5)
    assert m["resumed_after_s"] == pytest.approx(0.5)
    assert sensor_check("resumes_within_s", 1.0, m)[1] == (
        "drove 0.2 m towards the target 0.50 s after the obstacle left (limit 1.0 s)"
    )


def test_a_run_that_ends_before_the_limit_has_passed_is_not_judged():
    # Removed at 1.0 s, the robot standing still, the run's last row at 3.0 s, a row every
    # 0.5 s: the run ends at 3.5 s, 2.5 s after the removal, so a limit of 3 s cannot have
    # been missed yet, while one of 2.5 s has (the run went on that long).
    t = [1.0, 1.5, 2.0, 2.5, 3.0]
    m = obstacle_metrics(_traj(t, [1.0] * 5, [3.0] * 5), REMOVED, 0.5)
    assert m["resumed_after_s"] is None and m["run_after_removal_s"] == pytest.approx(2.5)
    assert sensor_check("resumes_within_s", 3.0, m) == (
        None,
        (
            "the run ended 2.50 s after the obstacle left at 1.00 s, before the 3.0 s limit: "
            "no resumption to judge"
        ),
    )
    assert sensor_check("resumes_within_s", 2.5, m)[0] is False


def test_only_the_motion_along_the_direction_to_the_target_counts():
    # The target at (3, 0); the robot drives from (1, 0) 0.3 m a row along +y: 0.9 m of path.
    # Along the direction to the target at each step's start: (0, 0.3) . (2, 0) / 2 = 0, then
    # (0, 0.3) . (2, -0.3) / 2.0224 = -0.0445 (away), then less still: never 0.2 m towards it.
    t = [1.0, 1.5, 2.0, 2.5]
    m = obstacle_metrics(_traj(t, [1.0] * 4, [3.0] * 4, robot_y=[0.0, 0.3, 0.6, 0.9]), REMOVED, 0.5)
    assert m["resumed_after_s"] is None
    # The same path along +x, straight at the target: 0.3 m by the first step, at 1.5 s.
    m = obstacle_metrics(_traj(t, [1.0, 1.3, 1.6, 1.9], [3.0] * 4), REMOVED, 0.5)
    assert m["resumed_after_s"] == pytest.approx(0.5)


def test_never_removed_is_not_judged_and_no_target_never_resumes():
    m = obstacle_metrics(_traj([0, 1], [1.0, 2.0], [3.0, 3.0]), [], 1.0)
    ok, text = sensor_check("resumes_within_s", 5.0, m)
    assert not ok and "no furniture was removed" in text
    m = obstacle_metrics(_traj([1.0, 2.0], [1.0, 2.0], [np.nan] * 2), REMOVED, 1.0)
    assert m["resumed_after_s"] is None


def _rows(xs, ys, headings):
    return {
        "t": np.arange(len(xs)) * 0.1,
        "x": np.asarray(xs, float),
        "y": np.asarray(ys, float),
        "heading": np.asarray(headings, float),
    }


def test_lateral_error_and_time_off_a_straight_line_by_hand():
    from fpga_robotics.checks.sensor_metrics import line_metrics
    from fpga_robotics.loop.connectors import Mount
    from fpga_robotics.sim.world.markings import FloorLine

    tape = FloorLine("tape", ((0.0, 1.0), (4.0, 1.0)), 0.02)
    # One sensor 0.1 m ahead of the robot's centre, the robot heading +x: the sensor's
    # offset from y = 1 is the robot's. Offsets 0, 5 mm (on the 20 mm tape), 30 mm (off it).
    m = line_metrics(
        _rows([1.0, 1.1, 1.2], [1.0, 1.005, 0.97], [0.0] * 3), [tape], [Mount(forward=0.1)], 0.1
    )
    assert m["lateral_error_max_m"] == pytest.approx(0.03)
    assert m["lateral_error_mean_m"] == pytest.approx(0.035 / 3)
    assert m["off_line_s"] == pytest.approx(0.1)  # one row of 0.1 s off the tape
    assert m["laps"] is None  # an open line has no laps
    # Two sensors 10 mm either side: their centre is the robot's line; the one row with the
    # robot 30 mm off still has no sensor on the tape, the 15 mm row has one.
    m = line_metrics(
        _rows([1.0, 1.1], [1.015, 0.97], [0.0] * 2),
        [tape],
        [Mount(left=0.01), Mount(left=-0.01)],
        0.1,
    )
    assert m["off_line_s"] == pytest.approx(0.1)
    assert m["lateral_error_max_m"] == pytest.approx(0.03)
    # The checks judge the exact error: 0.03004 m exceeds a limit of 0.03 m, though it shows
    # as 0.03 to 4 decimals.
    m = line_metrics(_rows([1.0], [1.03004], [0.0]), [tape], [Mount(forward=0.1)], 0.1)
    assert m["lateral_error_max_m"] == pytest.approx(0.03004)
    assert sensor_check("max_lateral_error_m", 0.03, m)[0] is False


def test_laps_count_the_net_progress_around_a_closed_line():
    from fpga_robotics.checks.sensor_metrics import line_metrics
    from fpga_robotics.loop.connectors import Mount
    from fpga_robotics.sim.world.markings import FloorLine

    square = FloorLine("sq", ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)), 0.02, closed=True)
    # Round the 4 m square one and a half times counter-clockwise, 0.25 m a row.
    s = np.arange(0, 6.0 + 1e-9, 0.25)
    side, along = (s // 1) % 4, s % 1
    xs = np.choose(side.astype(int), [along, np.ones_like(s), 1 - along, np.zeros_like(s)])
    ys = np.choose(side.astype(int), [np.zeros_like(s), along, np.ones_like(s), 1 - along])
    m = line_metrics(_rows(xs, ys, np.zeros_like(s)), [square], [Mount()], 0.1)
    assert m["laps"] == 1 and m["off_line_s"] == 0 and m["lateral_error_max_m"] == 0
    # The same way back: still one whole lap (net progress, either direction).
    m = line_metrics(_rows(xs[::-1], ys[::-1], np.zeros_like(s)), [square], [Mount()], 0.1)
    assert m["laps"] == 1


@pytest.mark.timeout(120)
def test_a_run_that_lasts_the_limit_after_the_removal_is_judged(tmp_path):
    """The box leaves at 1 s of a 2 s run and the robot never moves (every base_dps 0): the
    run went on the whole 1 s limit after the removal (its last frame is at 1.967 s, the run
    ends at 2 s), so the robot failed to resume: a fail, not n/a."""
    from fpga_robotics.loop import run_scenario
    from fpga_robotics.scenario import load_scenario

    path = tmp_path / "still.toml"
    path.write_text(
        "[sim]\nduration = 2.0\n"
        "[design]\nbase_dps = [0, 0, 0, 0, 0, 0, 0, 0]\n"
        '[[room.furniture]]\nname = "box"\ncenter = [3.0, 1.0]\npresent_until = 1.0\n'
        "[[people]]\nwaypoints = [[4.0, 3.0]]\n"
        "[checks]\nresumes_within_s = 1.0\n"
    )
    r = run_scenario(load_scenario(str(path)), backend="model")
    assert r.summary["sim_time_s"] == 2.0 and r.summary["run_after_removal_s"] == 1.0
    (c,) = r.summary["checks"]
    assert (c["status"], c["text"]) == (
        "fail",
        (
            "the robot never drove 0.2 m towards the target after the obstacle left at 1.00 s "
            "(limit 1.0 s)"
        ),
    )
