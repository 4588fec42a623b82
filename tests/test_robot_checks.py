"""The robot-level checks the mutation campaign adds (fpga_robotics/checks/shipped.py), each
on a hand-made trajectory with the answer computed by hand: ``max_led_misplaced_fraction`` (the
lit LED is the one above the target), ``max_wheel_command_dps`` (no wheel command beyond a
limit) and ``max_search_travel_m`` (the robot turns in place while it searches)."""

import numpy as np
import pytest

from fpga_robotics.checks.summary import CHECK_OUTPUTS, CHECKS, compute_metrics, evaluate_checks

# 160 pixels wide, the default window (margin 16): LED k above columns 16 + 16k .. 31 + 16k;
# the border tolerance is 160 / 32 = 5 px.
W = 160


def _traj(columns, leds, found=True, motors=(0, 0), x=None):
    n = len(columns)
    return {
        "t": np.arange(n) / 30,
        "x": np.zeros(n) if x is None else np.asarray(x, float),
        "y": np.zeros(n),
        "driven_x": np.zeros(n) if x is None else np.asarray(x, float),
        "driven_y": np.zeros(n),
        "found": np.broadcast_to(np.asarray(found), (n,)).copy(),
        "target_distance": np.ones(n),
        "target_in_view": np.ones(n, bool),
        "target_column": np.asarray(columns, dtype=float),
        "centroid_leds": np.asarray(leds),
        "centroid_x": np.full(n, 80),
        "motor_left": np.full(n, motors[0]),
        "motor_right": np.full(n, motors[1]),
    }


def _check(name, limit, m):
    (c,) = evaluate_checks({name: limit}, m)
    return c


def test_the_lit_led_must_be_the_one_above_the_target():
    columns = [
        24,  # bin 0 (16..31), far from a border
        24,
        40,  # bin 1
        120,  # bin 6 (112..127)
        110,  # bin 5, 2 px from the border at 112: bit 5 or bit 6
        110,
        110,
        82,  # bin 4, 2 px right of the centre: bit 4, bit 3 or the middle pair
        82,
        90,  # bin 4, 10 px from the centre: the middle pair is wrong here
        150,  # outside the window (columns 16..143): not judged
        np.nan,
    ]  # out of view: not judged
    leds = [
        0b0000_0001,  # right
        0b0000_0010,  # one bin off: misplaced
        0b0000_0011,  # two LEDs: misplaced
        0b0000_0000,  # dark while found: misplaced
        0b0010_0000,  # bit 5: right
        0b0100_0000,  # bit 6 (the neighbour across the border): right
        0b0001_0000,  # bit 4: misplaced
        0b0001_1000,  # middle pair near the centre: right
        0b0000_1000,  # bit 3 (across the centre border): right
        0b0001_1000,  # middle pair 10 px off: misplaced
        0b1000_0000,
        0b1000_0000,
    ]
    m = compute_metrics(_traj(columns, leds), [], {}, 1 / 30, width=W)
    assert m["led_misplaced_fraction"] == pytest.approx(round(5 / 10, 4))
    assert _check("max_led_misplaced_fraction", 0.5, m)["passed"]
    c = _check("max_led_misplaced_fraction", 0.4, m)
    assert not c["passed"] and "50.0% of the frames judged" in c["text"]


def test_a_lit_strip_may_light_the_led_above_any_column_of_the_suit():
    # A suit from column 40 to 100 (middle 70, bin 3) of which only a lit strip may match:
    # the centroid anywhere on it, so bits 1 (32..47) to 5 (96..111) are right, and the
    # middle pair (the centre, 80, is on it); bit 6 (112..127, 12 px beyond its edge) is not.
    traj = _traj([70] * 5, [0b10, 0b10_0000, 0b1_1000, 0b100_0000, 0b1])
    traj["target_left"], traj["target_right"] = np.full(5, 40.0), np.full(5, 100.0)
    lit = np.ones(5, bool)
    m = compute_metrics(traj, [], {}, 1 / 30, width=W, lit_strip=lit)
    assert m["led_misplaced_fraction"] == pytest.approx(2 / 5)
    # Judged by the suit's middle, as when every band matches surely: only bit 3 is right.
    m = compute_metrics(traj, [], {}, 1 / 30, width=W)
    assert m["led_misplaced_fraction"] == 1.0


def test_the_led_bins_follow_the_design_window():
    # margin 32: the window is 32..127, bins of 12 columns; column 40 is in bin 0 (32..43),
    # 4 px from the border at 44: bit 0 or bit 1; column 62 is in bin 2 (56..67), 6 px from
    # both its borders: bit 2 only.
    m = compute_metrics(
        _traj([40, 62, 62], [0b1, 0b100, 0b10]), [], {}, 1 / 30, width=W, margin_x=32
    )
    assert m["led_misplaced_fraction"] == 1 / 3
    # With the default margin (16) column 40 is bin 1 and 60 bin 2: bit 0 is misplaced.
    m = compute_metrics(_traj([40, 60], [0b1, 0b100]), [], {}, 1 / 30, width=W)
    assert m["led_misplaced_fraction"] == pytest.approx(0.5)


def test_leds_not_judged_without_found_frames_or_leds():
    m = compute_metrics(_traj([24, 40], [0, 0], found=False), [], {}, 1 / 30, width=W)
    assert m["led_misplaced_fraction"] is None
    c = _check("max_led_misplaced_fraction", 0.0, m)
    # Nothing to judge: n/a with the reason, neither a pass nor a failure.
    assert c["status"] == "n/a" and c["passed"] is None
    assert c["text"] == c["reason"] == "the target was never found inside the window"
    traj = _traj([24], [1])
    traj["centroid_leds"] = np.full(1, np.nan)
    m = compute_metrics(traj, [], {}, 1 / 30, width=W, absent={"centroid_leds"})
    assert m["led_misplaced_fraction"] is None
    assert _check("max_led_misplaced_fraction", 0.0, m)["passed"] is None


def test_the_largest_wheel_command_either_way():
    traj = _traj([80] * 4, [0b1_1000] * 4)
    traj["motor_left"] = np.array([100, 512, -30, 0])
    traj["motor_right"] = np.array([100, -250, -2298, 0])
    m = compute_metrics(traj, [], {}, 1 / 30, width=W)
    assert m["peak_wheel_command_dps"] == 2298
    c = _check("max_wheel_command_dps", 512, m)
    assert not c["passed"] and c["text"] == "largest wheel command 2298 DPS (limit <= 512 DPS)"
    assert _check("max_wheel_command_dps", 2298, m)["passed"]
    # A design without one wheel's output: not measured.
    traj["motor_right"] = np.full(4, np.nan)
    m = compute_metrics(traj, [], {}, 1 / 30, width=W, absent={"motor_right"})
    assert m["peak_wheel_command_dps"] is None
    assert _check("max_wheel_command_dps", 512, m)["passed"] is None


def test_the_robot_travels_little_while_it_searches():
    # x moves 0.1 m a frame in frames 0..3, stands in 3..5, moves 0.05 m a frame from 5 on.
    x = [0.0, 0.1, 0.2, 0.3, 0.3, 0.3, 0.35, 0.4, 0.45, 0.5]
    traj = _traj([80] * 10, [0] * 10, x=x)
    # A search from frame 2 to the target found at frame 4: 0.1 m (2 -> 3) + 0 (3 -> 4);
    # another from frame 6 to the end (frame 9): 3 x 0.05 = 0.15 m.
    events = [
        (1, 1 / 30, "target lost"),
        (2, 2 / 30, "search started"),
        (4, 4 / 30, "target found"),
        (5, 5 / 30, "target lost"),
        (6, 6 / 30, "search started"),
    ]
    m = compute_metrics(traj, events, {}, 1 / 30, width=W)
    assert m["search_travel_m"] == pytest.approx(0.15)
    c = _check("max_search_travel_m", 0.1, m)
    assert not c["passed"] and "drove 0.15 m during a search" in c["text"]
    assert _check("max_search_travel_m", 0.2, m)["passed"]
    # Never searched: nothing to judge, the check is n/a.
    m = compute_metrics(traj, events[:1], {}, 1 / 30, width=W)
    assert m["search_travel_m"] is None
    c = _check("max_search_travel_m", 0.1, m)
    assert c["text"] == "the design never searched" and c["status"] == "n/a"


def test_a_push_during_a_search_is_not_the_robots_travel():
    # A person shoves the robot 0.1 m a frame through a search (frames 2..6) while its own
    # driving moves it 0.02 m a frame: 4 x 0.02 m of its own.
    traj = _traj([80] * 8, [0] * 8, x=np.arange(8) * 0.1)
    traj["driven_x"] = np.arange(8) * 0.02
    events = [(2, 2 / 30, "search started"), (6, 6 / 30, "target found")]
    m = compute_metrics(traj, events, {}, 1 / 30, width=W)
    assert m["search_travel_m"] == pytest.approx(0.08)


def test_the_new_checks_are_declared_with_their_outputs():
    for name in ("max_led_misplaced_fraction", "max_wheel_command_dps", "max_search_travel_m"):
        assert name in CHECKS
    assert CHECK_OUTPUTS["max_led_misplaced_fraction"] == ("found", "centroid_leds")
    assert CHECK_OUTPUTS["max_wheel_command_dps"] == ("motor_left", "motor_right")
