"""Behaviour envelopes on hand-made trajectories, with bands worked out by hand from the
camera's geometry and the design's parameters: the defaults, and changed parameters that move
each band."""

import dataclasses
import math

import numpy as np
import pytest

from fpga_robotics.checks.envelopes import (
    EnvelopeGeometry,
    count_bounds,
    envelope_metrics,
    stop_distance_m,
)
from fpga_robotics.checks.registry import evaluate_checks
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.camera.raster import render
from fpga_robotics.sim.camera.scene import Band, CameraPose, Cylinder, Lighting, Scene

RED = 0b100
#: f = 80 / tan(hfov / 2) = 160 px; the camera 0.5 m up, level; a target 0.2 m in radius,
#: one red band from the floor to 1 m.
GEOM = EnvelopeGeometry(
    width=160,
    height=120,
    hfov=2 * math.atan(0.5),
    mount_height=0.5,
    mount_forward=0.0,
    tilt=0.0,
    radius=0.2,
    bands_sure={c: ([(0.0, 1.0)] if c == RED else []) for c in range(8)},
    bands_maybe={c: ([(0.0, 1.0)] if c == RED else []) for c in range(8)},
)
DEFAULT = FollowTargetParams()


def test_count_bounds_at_4_m_by_hand():
    # Half-width f tan(asin(0.2 / 4)) = 8.01 px: 16.02 columns. The body's depths lie between
    # its nearest point (3.8 m) and its axis (4 m). Rows at 4 m: 60 -+ 160 * 0.5 / 4 = 40..80
    # (40 rows); at 3.8 m 38.95..81.05 (42.1 rows); window rows 8..112.
    # lo = (16.02 - 2) * (40 - 2) = 532.8, hi = (16.02 + 2) * (42.1 + 2) = 794.7.
    assert count_bounds(4.0, 0.0, RED, GEOM, DEFAULT) == (532, 795)
    assert count_bounds(4.0, 0.0, 0b010, GEOM, DEFAULT) == (0, 0)  # no green band
    # The silhouette leaves the window (columns 16..144) past a bearing of ~0.4 rad.
    assert count_bounds(4.0, 0.45, RED, GEOM, DEFAULT) is None


def test_count_bounds_of_a_band_cut_by_the_window_top_by_hand():
    # A band from 1 to 2 m (0.5..1.5 m above the camera) 2.2 m away: depths from 2.0 m (the
    # nearest point) to 2.2 m (the axis). Its top row 60 - 160 * 1.5 / p is above the window's
    # top row 8 at both; its bottom row 60 - 80 / p is 20 at 2.0 m and 23.64 at 2.2 m: the
    # farther a column's depth the more rows it holds (12 at 2.0 m, 15.64 at 2.2 m). Columns
    # 320 tan(asin(0.2 / 2.2)) = 29.21. lo = (29.21 - 2) * (12 - 2) = 272.1,
    # hi = (29.21 + 2) * (15.64 + 2) = 550.5.
    geom = dataclasses.replace(
        GEOM, bands_sure={RED: [(1.0, 2.0)]}, bands_maybe={RED: [(1.0, 2.0)]}
    )
    assert count_bounds(2.2, 0.0, RED, geom, DEFAULT) == (272, 551)


@pytest.mark.parametrize("tilt", [-0.35, 0.0, 0.3])
@pytest.mark.parametrize("mount_height", [0.1, 0.3, 0.9])
def test_count_bounds_hold_the_rendered_count(mount_height, tilt):
    """The pixels the renderer draws of a band, inside the window, lie within the bounds:
    bands cut by the window's top or bottom row, on either side of the camera, straight
    ahead and off to a side (a red band over a blue floor and under a blue ceiling, in even
    light: every red pixel is the band's)."""
    light = Lighting(ambient=1.0, intensity=0.0)
    width, height, hfov = 160, 120, 1.047
    window_rows = slice(DEFAULT.margin_y, height - DEFAULT.margin_y)
    window_cols = slice(width // 10, width - width // 10)
    for z0, z1 in [(0.0, 0.5), (0.2, 0.35), (0.85, 1.45), (1.2, 1.7), (0.0, 1.75)]:
        bands = {RED: [(z0, z1)]}
        geom = EnvelopeGeometry(width, height, hfov, mount_height, 0.0, tilt, 0.2, bands, bands)
        for distance in (0.6, 1.0, 1.9, 4.0):
            for bearing in (0.0, -0.3):
                bounds = count_bounds(distance, bearing, RED, geom, DEFAULT)
                if bounds is None:
                    continue
                person = Cylinder(
                    x=distance * math.cos(bearing),
                    y=distance * math.sin(bearing),
                    radius=0.2,
                    bands=(Band(z0, z1, (1.0, 0.0, 0.0)),),
                )
                blue = (0.0, 0.0, 1.0)
                scene = Scene(
                    cylinders=(person,), lighting=light, floor_color=blue, ceiling_color=blue
                )
                pose = CameraPose(0.0, 0.0, 0.0, height=mount_height, tilt=tilt)
                image = render(scene, pose, width, height, hfov)[window_rows, window_cols]
                count = int(np.count_nonzero(image[..., 0] > 128))
                assert bounds[0] <= count <= bounds[1], (z0, z1, distance, bearing)


def _traj(frames):
    """A trajectory from ``(found, target_y, motor_left, motor_right)`` per frame: the robot at
    the origin facing +x, the target 4 m ahead at ``target_y`` (left positive)."""
    n = len(frames)
    return {
        "t": np.arange(n) / 30,
        "x": np.zeros(n),
        "y": np.zeros(n),
        "driven_x": np.zeros(n),
        "driven_y": np.zeros(n),
        "heading": np.zeros(n),
        "found": np.array([f[0] for f in frames], bool),
        "target_x": np.full(n, 4.0),
        "target_y": np.array([f[1] for f in frames], float),
        "motor_left": np.array([f[2] for f in frames], float),
        "motor_right": np.array([f[3] for f in frames], float),
        "color_sel": np.full(n, RED),
    }


def test_approach_speed_and_reversing_default_and_changed_speed_table():
    # At 4 m every count the geometry allows (532..795) is level 3: base_dps[3] = 200 forward.
    traj = _traj(
        [
            (True, 0.0, 200, 200),
            (True, 0.0, 300, 300),
            (True, 0.0, -100, -100),
            (True, 0.0, 200, 200),
        ]
    )
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["approach_speed_violation_fraction"] == 0.5  # 300 and -100
    assert m["reverse_when_far_fraction"] == 0.25
    # Level 3 at 300 DPS: the band moves, the 300 DPS frame now keeps the law.
    faster = DEFAULT.replace(base_dps=(0, 400, 300, 300, 150, 100, -100, -150))
    m = envelope_metrics(traj, faster, GEOM)
    assert m["approach_speed_violation_fraction"] == 0.75
    assert (
        envelope_metrics(_traj([(True, 0.0, 300, 300)]), faster, GEOM)[
            "approach_speed_violation_fraction"
        ]
        == 0.0
    )
    # Thresholds halved (64, 128, 256, 512, ...): 532..795 is level 4, 150 DPS.
    halved = DEFAULT.replace(proximity_thresholds=(64, 128, 256, 512, 1024, 2048, 3072))
    m = envelope_metrics(_traj([(True, 0.0, 150, 150), (True, 0.0, 200, 200)]), halved, GEOM)
    assert m["approach_speed_violation_fraction"] == 0.5


def test_approach_speed_at_the_frames_camera_tilt():
    # On a ramp the camera looks 0.35 rad up (the trajectory's camera_tilt): at 4 m the band's
    # top (1 m) lands on row 60 + 160 tan(0.35 - atan(0.5 / 4)) = 96.7 (95.6 at 3.8 m), its
    # bottom below the window's last row 112: 15.3 rows (16.4). lo = 14.02 * 13.3 = 186,
    # hi = 18.02 * 18.4 = 331: levels 1..2, 300..400 DPS, where the level camera's 532..795
    # (level 3) allows 200 only.
    traj = _traj([(True, 0.0, 300, 300), (True, 0.0, 200, 200)])
    level = envelope_metrics(traj, DEFAULT, GEOM)
    assert level["approach_speed_violation_fraction"] == 0.5
    traj["camera_tilt"] = np.full(2, 0.35)
    assert envelope_metrics(traj, DEFAULT, GEOM)["approach_speed_violation_fraction"] == 0.5
    traj["motor_left"] = traj["motor_right"] = np.array([300.0, 400.0])
    assert envelope_metrics(traj, DEFAULT, GEOM)["approach_speed_violation_fraction"] == 0.0


def test_turn_law_default_and_changed_gain():
    # Target 0.4 m to the left at 4 m: bearing atan(0.1); silhouette columns
    # 80 - 160 tan(bearing +- asin(0.2 / 4.02)): centre column 63.97, e = 63.97 - 0.5 - 80
    # = -16.53 +- 2: turn 3e in [3 * -19, 3 * -14] = [-57, -42]; the robot turns left (L < R).
    y = 0.4
    good = (True, y, 200 - 48, 200 + 48)
    wrong_sign = (True, y, 200 + 48, 200 - 48)
    too_much = (True, y, 200 - 70, 200 + 70)
    m = envelope_metrics(_traj([good, wrong_sign, too_much, good]), DEFAULT, GEOM)
    assert m["turn_law_violation_fraction"] == 0.5
    # kp_num = 4: the band is [-76, -56]; 70 keeps it, 48 breaks it.
    m = envelope_metrics(_traj([good, too_much]), DEFAULT.replace(kp_num=4), GEOM)
    assert m["turn_law_violation_fraction"] == 0.5
    assert (
        envelope_metrics(_traj([too_much]), DEFAULT.replace(kp_num=4), GEOM)[
            "turn_law_violation_fraction"
        ]
        == 0.0
    )


def test_turn_law_of_a_suit_whose_shaded_side_may_drop_out():
    # The band matches only in some light (lower bound 0): only a lit strip may match, so the
    # centroid may lie anywhere across the silhouette, columns 71.49..87.51 at 4 m straight
    # ahead: e = -0.5 +- (2 + 16.02 / 2), turn 3e in [-33, 30]. The lit right edge's centroid
    # at 87 (e = 7, turn 21, beyond a quarter of the width's 18) keeps the law.
    shaded = dataclasses.replace(GEOM, bands_sure={c: [] for c in range(8)})
    traj = _traj([(True, 0.0, 221, 179), (True, 0.0, 230, 170), (True, 0.0, 231, 169)])
    assert envelope_metrics(traj, DEFAULT, shaded)["turn_law_violation_fraction"] == 1 / 3


def test_a_suit_matching_only_between_the_darkest_and_brightest_light():
    """A salmon suit in bright light matches the red filter from shade 0.8 to 1.7 only, not
    in ambient alone (0.5) nor in the brightest light (1.8: R saturates, G goes on rising):
    the bounds count it, and the design's approach keeps the law."""
    s = load_scenario(
        "approach",
        [
            "people.0.shirt_color=[0.85,0.35,0.3]",
            "people.0.trousers_color=[0.85,0.35,0.3]",
            "lighting.ambient=0.5",
            "lighting.intensity=1.3",
            "sim.duration=1",
            "checks={}",
        ],
    )
    m = run_scenario(s, backend="model").summary
    assert m["found_fraction"] == 1.0
    assert m["approach_speed_violation_fraction"] == 0.0


def test_search_law_default_and_changed_search():
    # Seen on the right (y < 0), then lost: lost frames 1..14 hold (152, 248 here), frame 15
    # on turns right in place at 250 DPS: left +250, right -250.
    seen = (True, -0.4, 248, 152)
    hold = (False, -0.4, 248, 152)
    search = (False, -0.4, 250, -250)
    left_search = (False, -0.4, -250, 250)
    frames = [seen] + [hold] * 14 + [search] * 5
    assert envelope_metrics(_traj(frames), DEFAULT, GEOM)["search_law_violation_fraction"] == 0
    wrong = [seen] + [hold] * 14 + [left_search] * 5
    assert envelope_metrics(_traj(wrong), DEFAULT, GEOM)["search_law_violation_fraction"] == 5 / 19
    early = [seen] + [hold] * 10 + [search] * 9
    assert envelope_metrics(_traj(early), DEFAULT, GEOM)["search_law_violation_fraction"] == 4 / 19
    # lost_frames = 11 and search_dps = 100: the search starts at the 11th lost frame.
    changed = DEFAULT.replace(lost_frames=11, search_dps=100)
    early_slow = [seen] + [hold] * 10 + [(False, -0.4, 100, -100)] * 9
    assert envelope_metrics(_traj(early_slow), changed, GEOM)["search_law_violation_fraction"] == 0
    assert (
        envelope_metrics(_traj(early), changed, GEOM)["search_law_violation_fraction"] == 9 / 19
    )  # 250
    # After reset, never seen: the search turns left.
    never = [(False, 0.0, 0, 0)] * 14 + [(False, 0.0, -250, 250)] * 3
    assert envelope_metrics(_traj(never), DEFAULT, GEOM)["search_law_violation_fraction"] == 0


def _lo(d):
    """The lower count bound straight ahead, from the geometry by hand (rows unclipped)."""
    cols = 2 * 160 * math.tan(math.asin(0.2 / d))
    return (cols - 2) * (160 * 0.5 / d + 160 * 0.5 / d - 2)


def _solve(f, threshold, a=0.5, b=20.0):
    for _ in range(60):  # bisection: f decreases with the distance
        mid = (a + b) / 2
        a, b = (mid, b) if f(mid) >= threshold else (a, mid)
    return a


def test_stop_distance_moves_with_the_reversing_threshold():
    # Level 6 (base -100) at 1000 px: lo(d) = 1000 at d = 3.09 m (rows unclipped there).
    params = DEFAULT.replace(proximity_thresholds=(128, 256, 400, 600, 800, 1000, 1200))
    near, far = stop_distance_m(GEOM, params, RED)
    assert near == pytest.approx(_solve(_lo, 1000), abs=0.006)
    # The law reversing one level later (level 7 at 1200 px) stops the robot closer.
    later = params.replace(base_dps=(0, 400, 300, 200, 150, 100, 50, -150))
    near7, _ = stop_distance_m(GEOM, later, RED)
    assert near7 == pytest.approx(_solve(_lo, 1200), abs=0.006)
    assert near7 < near < far
    # Never stopping: no stop distance.
    assert (
        stop_distance_m(GEOM, DEFAULT.replace(base_dps=(1, 400, 300, 200, 150, 100, 50, 40)), RED)
        is None
    )


def _on_the_axis(robot_x, target_x):
    """The robot at ``robot_x`` and the target at ``target_x`` on the x axis, per frame, the
    robot facing it (+x) and the target found in every frame (GEOM: the camera at the
    robot's centre)."""
    traj = _traj([(True, 0.0, 0, 0)] * len(robot_x))
    traj["x"] = traj["driven_x"] = np.array(robot_x, float)
    traj["target_x"] = np.array(target_x, float)
    return traj


#: GEOM's stop distance with the default law: 1.53 m (test_stop_distance_...: lo(d) reaches
#: the level-6 threshold there), surely driving on beyond 1.745 m.
NEAR = 1.53


@pytest.mark.parametrize(
    "robot_x, target_x, overshoot, closest",
    [
        # Drives in from 2 m to 1.3 m, then backs off: 1.53 - 1.3 m, all its own driving.
        ([0.0, 0.3, 0.6, 0.7, 0.6], [2.0] * 5, 0.23, 1.3),
        # Starts 1.3 m away, inside, and backs off: it drove nothing inside.
        ([0.7, 0.65, 0.6, 0.5], [2.0] * 4, 0.0, 1.3),
        # The target walks up from 2 m to 1.28 m while the robot backs off 2 cm a frame.
        ([0.0, -0.02, -0.04, -0.06, -0.08], [2.0, 1.8, 1.6, 1.4, 1.2], 0.0, 1.28),
        # Starts inside at 1.3 m and drives 0.1 m further in: the law said stop.
        ([0.7, 0.75, 0.8], [2.0] * 3, 0.1, 1.2),
        # Both close in from 1.6 m: the target 0.1 m a frame, the robot 0.05 m, its three
        # steps (0.15 m) inside (1.45, 1.3 and 1.15 m) its own.
        ([0.0, 0.05, 0.10, 0.15], [1.6, 1.5, 1.4, 1.3], 0.15, 1.15),
    ],
)
def test_stop_overshoot_counts_the_robots_own_driving_inside(robot_x, target_x, overshoot, closest):
    assert stop_distance_m(GEOM, DEFAULT, RED)[0] == NEAR
    m = envelope_metrics(_on_the_axis(robot_x, target_x), DEFAULT, GEOM)
    assert m["stop_overshoot_m"] == pytest.approx(overshoot, abs=1e-9)
    assert (m["stop_distance_m"], m["stop_closest_m"]) == (NEAR, pytest.approx(closest))
    (c,) = evaluate_checks({"max_stop_overshoot_m": 0.05}, m)
    assert c["passed"] == (overshoot <= 0.05)
    assert c["text"] == (
        f"drove {overshoot:.3f} m inside the stop distance (stop distance 1.530 m, closest "
        f"{closest:.3f} m, camera to the target's centre; limit <= 0.05 m)"
    )


@pytest.mark.parametrize(
    "driven_x, overshoot",
    [
        # Backing off 2 cm a frame while a person shoves it in from 2 m to 1.3 m: it drove
        # nothing inside.
        ([0.0, -0.02, -0.04, -0.06], 0.0),
        # Creeping in 5 cm a frame while shoved in 0.3 m a frame: its own two steps inside
        # (to 1.4 m and 1.3 m) count, the push does not.
        ([0.0, 0.05, 0.10, 0.15], 0.10),
    ],
)
def test_stop_overshoot_leaves_out_a_push(driven_x, overshoot):
    traj = _on_the_axis([0.0, 0.3, 0.6, 0.7], [2.0] * 4)
    traj["driven_x"] = np.array(driven_x, float)
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["stop_overshoot_m"] == pytest.approx(overshoot, abs=1e-9)
    assert m["stop_closest_m"] == pytest.approx(1.3)


def test_stop_overshoot_of_a_robot_a_passer_by_shoves_towards_the_target(tmp_path):
    """The robot starts 1.9 m from the red target (stop distance 1.14 m) and obeys the law;
    a passer-by walks into it from behind at 0.8 m/s and pushes it to 0.49 m (camera to the
    target's centre): it drove (next to) nothing inside."""
    path = tmp_path / "pushed.toml"
    path.write_text(
        """
[sim]
duration = 5.0
[robot]
start = [1.6, 3.0]
[[people]]
shirt_color = [0.85, 0.1, 0.1]
trousers_color = [0.8, 0.1, 0.1]
waypoints = [[3.5, 3.0]]
[[people]]
name = "blue"
target = false
shirt_color = [0.2, 0.3, 0.8]
waypoints = [[0.4, 3.0], [2.4, 3.0]]
speed = 0.8
loop = false
start_delay = 1.0
[checks]
max_stop_overshoot_m = 0.05
"""
    )
    m = run_scenario(load_scenario(str(path)), backend="model").summary
    assert m["stop_closest_m"] < 0.6
    assert m["stop_overshoot_m"] < 0.005  # the old measure: 0.65 m
    assert m["verdict"] == "pass"


def test_stop_overshoot_uses_the_colour_followed_in_each_frame():
    # The first case above, but the first frame follows green (no green band: no stop
    # distance) before the design switches to red: the same 0.23 m inside red's stop distance.
    traj = _on_the_axis([0.0, 0.3, 0.6, 0.7, 0.6], [2.0] * 5)
    traj["color_sel"][0] = 0b010
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["stop_overshoot_m"] == pytest.approx(0.23, abs=1e-9)
    assert (m["stop_distance_m"], m["stop_closest_m"]) == (NEAR, pytest.approx(1.3))


@pytest.mark.parametrize(
    "params, colour, reason",
    [
        (
            DEFAULT.replace(base_dps=(0, 400, 300, 200, 150, 100, 100, 100)),
            RED,
            "the law never stops near the target (no base_dps <= 0 at proximity levels 1..7)",
        ),
        (
            DEFAULT,
            0b010,
            (
                "the law never stops for the colour followed (its count never reaches the "
                "stopping level's threshold)"
            ),
        ),
        (DEFAULT, RED, "the robot never came near the stop distance"),
    ],
)
def test_stop_overshoot_na_says_why(params, colour, reason):
    # Driving from 3 m to 2.7 m, beyond red's stop distance (surely driving on past 1.745 m).
    traj = _on_the_axis([0.0, 0.1, 0.2, 0.3], [3.0] * 4)
    traj["color_sel"][:] = colour
    (c,) = evaluate_checks({"max_stop_overshoot_m": 0.05}, envelope_metrics(traj, params, GEOM))
    assert c["status"] == "n/a" and c["reason"] == reason


@pytest.mark.parametrize(
    "exposure_s, unsure",
    [
        (0.0, "the suit's colour is not sure to match at every shade of the scenario's light"),
        (1 / 30, "camera.sensor's exposure and white balance move the suit's colour"),
    ],
)
def test_stop_overshoot_na_when_no_band_is_sure_to_match(exposure_s, unsure):
    # Red may match (the upper bound reaches the stopping level within 1.745 m) but no band
    # surely does: the law may well stop, only not at a distance the bounds can say.
    geom = dataclasses.replace(GEOM, bands_sure={c: [] for c in range(8)}, exposure_s=exposure_s)
    assert stop_distance_m(geom, DEFAULT, RED) == (None, stop_distance_m(GEOM, DEFAULT, RED)[1])
    traj = _on_the_axis([0.0, 0.3, 0.6, 0.7, 0.6], [2.0] * 5)
    (c,) = evaluate_checks({"max_stop_overshoot_m": 0.05}, envelope_metrics(traj, DEFAULT, geom))
    assert c["status"] == "n/a"
    assert c["reason"] == f"the stop distance cannot be bounded: {unsure}"


def test_stop_overshoot_of_a_robot_put_inside_the_stop_distance():
    """approach with the person 1.0 m ahead (centres): the camera, 0.1 m ahead of the
    centre, starts 0.9 m from them, inside the 1.14 m stop distance, and the design backs
    off from the first frame: closest 0.9 m, nothing driven inside."""
    s = load_scenario(
        "approach", ["people.0.waypoints=[[2.5, 3.0]]", "sim.duration=1", "checks={}"]
    )
    m = run_scenario(s, backend="model").summary
    assert m["stop_distance_m"] > 1.0
    assert m["stop_closest_m"] == pytest.approx(0.9, abs=1e-6)
    assert m["stop_overshoot_m"] == 0.0


def test_frames_the_interlock_holds_are_not_judged():
    # follow_target_safe: at 4 m the law says 200 forward (level 3); with ``obstacle`` 1 the
    # interlock holds the wheels at 0, which is right. The loss that begins after it holds the
    # inner design's command (200), not the 0 shown: its hold is not judged.
    traj = _traj(
        [(True, 0.0, 200, 200), (True, 0.0, 0, 0), (False, 0.0, 200, 200), (True, 0.0, 200, 200)]
    )
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["approach_speed_violation_fraction"] == pytest.approx(1 / 3)
    assert m["search_law_violation_fraction"] == 1.0
    traj["design.obstacle"] = np.array([0.0, 1.0, 0.0, 0.0])
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["approach_speed_violation_fraction"] == 0.0
    assert m["search_law_violation_fraction"] is None


def test_a_failing_envelope_names_its_frames_and_the_first_violation():
    # At 4 m every count is level 3: 200 forward, no turn straight ahead. Frame 2 (t = 2/30 s)
    # is the first of two at 300; then the target is lost: frame 4 holds (300, 300), frame 5
    # does not.
    traj = _traj(
        [
            (True, 0.0, 200, 200),
            (True, 0.0, 200, 200),
            (True, 0.0, 300, 300),
            (True, 0.0, 300, 300),
            (False, 0.0, 300, 300),
            (False, 0.0, 0, 0),
        ]
    )
    m = envelope_metrics(traj, DEFAULT, GEOM)
    (speed, search) = evaluate_checks(
        {"max_approach_speed_violation_fraction": 0.0, "max_search_law_violation_fraction": 0.0},
        m,
    )
    assert speed["text"] == (
        "forward speed outside the approach law in 2 of 4 centred frames (50.0%), first at "
        "0.07 s (frame 2): 300 DPS, law 200..200 (levels 3..3 at 4.00 m) (limit <= 0%)"
    )
    assert search["text"] == (
        "lost/search command off the law in 1 of 2 lost frames judged (50.0%), first at 0.17 s "
        "(frame 5): wheels 0, 0 DPS, law 300, 300 (limit <= 0%)"
    )


def test_other_laws_leave_the_envelopes_na():
    traj = _traj([(True, 0.0, 200, 200)])
    m = envelope_metrics(traj, FollowTargetParams.published(), GEOM)
    assert "table" in m["envelope_reason"]
    (c,) = evaluate_checks({"max_approach_speed_violation_fraction": 0.0}, m)
    assert c["status"] == "n/a" and "no envelope" in c["reason"]
    m = envelope_metrics(traj, DEFAULT, GEOM)
    (c,) = evaluate_checks({"max_approach_speed_violation_fraction": 0.0}, m)
    assert c["status"] == "pass"


def test_no_geometry_leaves_the_envelopes_na_with_its_reason():
    m = envelope_metrics(_traj([(True, 0.0, 200, 200)]), DEFAULT, "no target person")
    assert m["envelope_reason"] == "no target person"
    assert m["approach_speed_violation_fraction"] is None
    (c,) = evaluate_checks({"max_turn_law_violation_fraction": 0.0}, m)
    assert c["status"] == "n/a" and c["reason"] == "no envelope: no target person"


def _leaving(distance, bearing, search):
    """Seen once at ``distance`` (m) and ``bearing`` (rad, left positive), then lost: 14 held
    frames and 5 of ``search`` (motor_left, motor_right)."""
    traj = _traj(
        [(True, 0.0, 248, 152)] + [(False, 0.0, 248, 152)] * 14 + [(False, 0.0, *search)] * 5
    )
    traj["target_x"][:] = distance * math.cos(bearing)
    traj["target_y"][:] = distance * math.sin(bearing)
    return traj


def test_search_side_of_a_target_leaving_the_view():
    # 1 m away at a bearing of -0.55 rad, its centre beyond the half field of view (0.4636 rad):
    # the silhouette's half-angle asin(0.2) = 0.2014 rad puts its columns at
    # 80 + 160 tan(0.3486) = 138.2 to 80 + 160 tan(0.7514) = 229.9. The part inside the window
    # (columns 16..144) is 138.2..144, all right of the centre (80): the search turns right.
    right, left = (250, -250), (-250, 250)
    m = envelope_metrics(_leaving(1.0, -0.55, right), DEFAULT, GEOM)
    assert m["search_law_violation_fraction"] == 0
    m = envelope_metrics(_leaving(1.0, -0.55, left), DEFAULT, GEOM)
    assert m["search_law_violation_fraction"] == 5 / 19
    # A search 2 DPS off search_dps is off the law as well.
    m = envelope_metrics(_leaving(1.0, -0.55, (248, -250)), DEFAULT, GEOM)
    assert m["search_law_violation_fraction"] == 5 / 19
    # The mirror image: leaving on the left, the search turns left.
    assert (
        envelope_metrics(_leaving(1.0, 0.55, left), DEFAULT, GEOM)["search_law_violation_fraction"]
        == 0
    )
    assert (
        envelope_metrics(_leaving(1.0, 0.55, right), DEFAULT, GEOM)["search_law_violation_fraction"]
        == 5 / 19
    )
    # margin_x = 64: the window is columns 64..96 and the silhouette (138.2..229.9) lies
    # wholly outside it; the last sighting has no sure side, only the 14 held frames count.
    narrow = DEFAULT.replace(margin_x=64)
    for search in (right, left):
        m = envelope_metrics(_leaving(1.0, -0.55, search), narrow, GEOM)
        assert m["search_law_violation_fraction"] == 0


def test_search_side_unsure_when_the_visible_part_spans_the_centre():
    # 0.5 m away at -0.3 rad: half-angle asin(0.4) = 0.4115 rad, columns
    # 80 - 160 tan(0.1115) = 62.1 to 80 + 160 tan(0.7115) = 217.9; inside the window 62.1..144
    # spans the centre, so the centroid's side is not sure: either search passes.
    for search in ((250, -250), (-250, 250)):
        m = envelope_metrics(_leaving(0.5, -0.3, search), DEFAULT, GEOM)
        assert m["search_law_violation_fraction"] == 0


def test_search_side_tolerates_the_smear_of_a_turn():
    # 4 m ahead, 5 px right of the centre (y = -4 * 5 / 160 = -0.125 m): the side is sure with
    # E_TOLERANCE_PX (2 px). With the sensor model's exposure (1/30 s) and the robot turning at
    # 2 rad/s, half the smear is 2 * (1/30) * 160 / 2 = 5.33 px: 7.33 px in all, no sure side.
    sensor = dataclasses.replace(GEOM, exposure_s=1 / 30)
    wrong = [(True, -0.125, 248, 152)] + [(False, -0.125, 248, 152)] * 14
    wrong += [(False, -0.125, -250, 250)] * 5
    for w, judged_wrong in ((0.0, 5), (1.0, 5), (2.0, 0)):
        traj = _traj(wrong)
        traj["w"] = np.full(len(wrong), w)
        m = envelope_metrics(traj, DEFAULT, sensor)
        assert m["search_law_violation_fraction"] == judged_wrong / (14 + judged_wrong)


def test_search_side_of_a_lit_strip_is_sure_only_off_the_silhouette():
    # 1 m ahead, 0.05 m left: half-angle asin(0.2) = 0.2014 rad around a bearing of 0.05 rad,
    # columns 80 - 160 tan(0.2514) = 38.9 to 80 + 160 tan(0.1514) = 104.4, middle 71.6 (left
    # of the centre). With every band sure to match the search turns left; with red matching
    # only in some light, a lit strip may be anywhere on 38.9..104.4, across the centre: no
    # sure side. 4 m ahead, 0.3 m left (columns 59.9..76.1) it is left either way.
    strip = dataclasses.replace(GEOM, bands_sure={c: [] for c in range(8)})
    for distance, y, geom, judged_wrong in (
        (1.0, 0.05, GEOM, 5),
        (1.0, 0.05, strip, 0),
        (4.0, 0.3, strip, 5),
    ):
        wrong = [(True, y, 0, 0)] + [(False, y, 0, 0)] * 14 + [(False, y, 250, -250)] * 5
        traj = _traj(wrong)
        traj["target_x"][:] = distance
        m = envelope_metrics(traj, DEFAULT, geom)
        assert m["search_law_violation_fraction"] == judged_wrong / (14 + judged_wrong)


def test_a_partly_hidden_target_leaves_the_count_and_centroid_unsure():
    # At 4 m straight ahead the count allows level 3 only (200 DPS forward, no turn). With
    # part of the target hidden (``target_hidden``) any count up to the upper bound may be
    # seen: levels 0..3, 0..400 DPS forward; the centroid anywhere on the silhouette
    # (72.0..88.0, e -8..8 +- 2 px): turns of 3 * -10 .. 3 * 10 DPS allowed, not only
    # 3 * -2 .. 3 * 2.
    frames = [(True, 0.0, 320, 280), (True, 0.0, 150, 150), (True, 0.0, 400, 400)]
    traj = _traj(frames)
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["approach_speed_violation_fraction"] == 1.0
    assert m["turn_law_violation_fraction"] == 1 / 3
    traj["target_hidden"] = np.ones(3, bool)
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["approach_speed_violation_fraction"] == 0.0
    assert m["turn_law_violation_fraction"] == 0.0
    # Reversing while far is still judged: a hidden part only lowers the count.
    traj = _traj([(True, 0.0, -100, -100)])
    traj["target_hidden"] = np.ones(1, bool)
    assert envelope_metrics(traj, DEFAULT, GEOM)["reverse_when_far_fraction"] == 1.0


CABINET = (
    "room.furniture=[{name='cabinet', type='box', center=[3.5, 3.0], size=[0.6, 1.2], height=1.8}]"
)


def test_a_target_passing_behind_a_cabinet_is_not_judged_by_its_hidden_part():
    """The robot faces a 1.8 m tall cabinet (x 3.2..3.8, y 2.4..3.6) with the target standing
    behind it, then walking out along x = 5.5: the envelopes judge the frames in which the
    cabinet's corner eats into the target's silhouette with the count and centroid unsure,
    and the default design keeps its laws."""
    s = load_scenario(
        "approach",
        [
            CABINET,
            "people.0.waypoints=[[5.5, 3.0], [5.5, 5.0]]",
            "people.0.speed=0.4",
            "people.0.start_delay=4.0",
            "people.0.pause=3.0",
            "sim.duration=15",
            "checks.max_approach_speed_violation_fraction=0.0",
            "checks.max_turn_law_violation_fraction=0.0",
        ],
    )
    r = run_scenario(s, backend="model")
    hidden, t = r.trajectory["target_hidden"], r.trajectory["t"]
    # Straight behind the cabinet, taller than the camera, while the robot looks at it from
    # about 1.6 m (its face 0.36 rad either side of the axis, the target's silhouette 0.05).
    assert hidden[t < 1.0].all()
    assert not hidden.all()
    checks = {c["name"]: c for c in r.summary["checks"]}
    assert checks["max_approach_speed_violation_fraction"]["passed"]
    assert checks["max_turn_law_violation_fraction"]["passed"]


def test_camera_noise_beyond_the_bounds_slack_leaves_the_envelopes_na():
    """lost_target's shaded suit at noise 10 loses enough pixels to the filter that its count
    leaves the bounds (the correct design's level 5 where they allow 6): n/a with the
    reason; the robustness campaign's noise 8 is judged."""
    base = ["sim.duration=0.2", "checks={}"]
    m = run_scenario(
        load_scenario("lost_target", [*base, "camera.noise_std=10"]), backend="model"
    ).summary
    assert m["approach_speed_violation_fraction"] is None
    assert "noise_std 8" in m["envelope_reason"] and "noise_std = 10" in m["envelope_reason"]
    (c,) = evaluate_checks({"max_approach_speed_violation_fraction": 0.0}, m)
    assert c["status"] == "n/a"
    m = run_scenario(
        load_scenario("lost_target", [*base, "camera.noise_std=8"]), backend="model"
    ).summary
    assert m["envelope_reason"] is None


def test_a_design_without_a_found_output_leaves_the_envelopes_na():
    """A design of one's own without ``found`` records NaN there: no frame counts as a
    sighting (NaN is not True), whatever its wheels do."""
    traj = _traj([(True, 0.0, 512, -512)] * 5)  # spinning at full speed: far outside the law
    assert envelope_metrics(traj, DEFAULT, GEOM)["turn_law_violation_fraction"] == 1.0
    traj["found"] = np.full(len(traj["found"]), np.nan)
    m = envelope_metrics(traj, DEFAULT, GEOM)
    assert m["envelope_reason"] == "the design has no found output"
    assert m["turn_law_violation_fraction"] is None
    assert m["approach_speed_violation_fraction"] is None
