"""``max_led_wrong_side_fraction``: the centroid LEDs on the robot point the right way
(fpga_robotics/checks/summary.py), checked on hand-made trajectories of a 160-pixel-wide image."""

import numpy as np

from fpga_robotics.checks.summary import compute_metrics, evaluate_checks

W = 160


def _traj(columns, leds, found=True):
    n = len(columns)
    return {
        "t": np.arange(n) / 30,
        "x": np.zeros(n),
        "y": np.zeros(n),
        "found": np.full(n, found),
        "target_distance": np.ones(n),
        "target_in_view": np.ones(n, bool),
        "target_column": np.asarray(columns, dtype=float),
        "centroid_leds": np.asarray(leds),
        "centroid_x": np.full(n, 80),
    }


def test_leds_on_the_other_half_or_outer_leds_at_the_centre_are_wrong():
    # Frames: target right (column 120 >= 80 + 20), left (30), centred (82), in between (95,
    # not judged: 15 px from the centre is neither within 10 nor beyond 20), out of view.
    columns = [120, 120, 30, 30, 82, 82, 82, 95, np.nan]
    leds = [
        0b1000_0000,  # right LED for a right target: fine
        0b0000_1000,  # bit 3 (left half) for a right target: wrong
        0b0000_0001,  # left for left: fine
        0b0001_0000,  # bit 4 (right half) for a left target: wrong
        0b0001_1000,  # centred: fine
        0b0000_0100,  # bit 2 at the centre: fine (a wide target)
        0b1000_0000,  # bit 7 at the centre: wrong
        0b0000_0001,  # not judged
        0b0000_0001,
    ]  # not judged (no target column)
    m = compute_metrics(_traj(columns, leds), [], {}, 1 / 30, width=W)
    assert m["led_wrong_side_fraction"] == 3 / 7
    (c,) = evaluate_checks({"max_led_wrong_side_fraction": 0.5}, m)
    assert c["passed"] and "43% of the frames judged" in c["text"]
    (c,) = evaluate_checks({"max_led_wrong_side_fraction": 0.4}, m)
    assert not c["passed"]


def test_a_lit_strip_across_the_centre_has_no_side():
    # Suits whose columns 102 and 58 are 22 px off the centre, of which only a lit strip may
    # match: one spanning 60..144 (across the centre, so a left LED is no fault) and one
    # 4..52 cut by the window at 16 (wholly left: a right LED is wrong); a suit 72..88 at the
    # centre, its centroid within 8 px: an outer LED is wrong.
    traj = _traj([102, 102, 58, 82], [0b1, 0b1000_0000, 0b1000_0000, 0b1000_0000])
    traj["target_left"] = np.array([60.0, 60.0, 4.0, 72.0])
    traj["target_right"] = np.array([144.0, 144.0, 52.0, 88.0])
    m = compute_metrics(traj, [], {}, 1 / 30, width=W, lit_strip=np.ones(4, bool))
    assert m["led_wrong_side_fraction"] == 1.0  # the last two, judged; the first two not
    m = compute_metrics(traj, [], {}, 1 / 30, width=W)
    assert m["led_wrong_side_fraction"] == 3 / 4  # by the middle: the first one is wrong


def test_not_judged_without_found_frames_or_without_the_leds():
    m = compute_metrics(_traj([120, 30], [0b1, 0b1], found=False), [], {}, 1 / 30, width=W)
    assert m["led_wrong_side_fraction"] is None
    (c,) = evaluate_checks({"max_led_wrong_side_fraction": 0.0}, m)
    assert c["passed"] is None and c["status"] == "n/a"  # nothing to judge: neither way
    assert c["text"] == "the target was never found to one side or at the centre"
    # A design without the LEDs: not measured (docs/foreign.md).
    traj = _traj([120], [0])
    traj["centroid_leds"] = np.full(1, np.nan)
    m = compute_metrics(traj, [], {}, 1 / 30, width=W, absent={"centroid_leds"})
    assert m["led_wrong_side_fraction"] is None
    (c,) = evaluate_checks({"max_led_wrong_side_fraction": 0.0}, m)
    assert c["passed"] is None
