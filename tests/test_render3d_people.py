"""People in the 3D renderer: their limbs swing with their speed (a standing person's are
still, a walking person's swing at ``speed / cycle_length`` cycles a second), the world keeps
what the gait needs, and the same seed gives the same frames."""

import math

import numpy as np
import pytest
from render3d_scenes import HFOV, POSE, H, W, mujoco_missing, person_scene

from fpga_robotics.sim.camera.render3d import cycle_length, gait_angles
from fpga_robotics.sim.camera.render3d.body import JOINTS, SWING
from fpga_robotics.sim.camera.render3d.textures import KINDS, modulation
from fpga_robotics.sim.world import World


def test_a_standing_person_holds_still():
    for walked in (0.0, 0.3, 1.7):
        angles = gait_angles(walked, 0.0, 1.75)
        assert set(angles) == set(JOINTS)
        for joint in ("hip_l", "hip_r", "knee_l", "knee_r", "shoulder_l", "shoulder_r"):
            assert angles[joint] == 0.0


def test_the_swing_grows_with_speed_up_to_full():
    # A quarter cycle in (sin = 1): the hip's forward swing is its amplitude.
    quarter = cycle_length(1.75) / 4
    slow, fast, faster = (gait_angles(quarter, v, 1.75)["hip_l"] for v in (0.1, 0.5, 1.2))
    assert slow == pytest.approx(SWING["hip"] * 0.1 / 0.5)
    assert fast == faster == pytest.approx(SWING["hip"])
    # Legs and arms swing against each other.
    a = gait_angles(quarter, 0.5, 1.75)
    assert (
        a["hip_r"] == -a["hip_l"]
        and a["shoulder_l"] == -a["hip_l"] * SWING["shoulder"] / SWING["hip"]
    )


def _crossings(values):
    s = np.sign(values)
    return int(np.count_nonzero(s[1:] * s[:-1] < 0))


@pytest.mark.parametrize("speed", [0.3, 0.6])
def test_a_walker_swings_at_speed_over_cycle_length(speed):
    # A person walking 10 m in a straight line at constant speed; the hip angle sampled at
    # 30 frames a second crosses zero twice a cycle: 2 * speed / cycle_length a second.
    world = World.from_config(
        {
            "room": {"width": 14.0},
            "robot": {"start": [0.5, 0.5]},
            "people": [{"waypoints": [[1.0, 3.0], [13.0, 3.0]], "speed": speed, "loop": False}],
        },
        0,
    )
    hips, seconds = [], 8.0
    for _ in range(int(seconds * 30)):
        world.step(1 / 30)
        (cyl,) = world.scene().cylinders
        assert cyl.speed == pytest.approx(speed)
        assert cyl.facing == pytest.approx(0.0)
        hips.append(gait_angles(cyl.walked, cyl.speed, 1.75)["hip_l"])
    assert cyl.walked == pytest.approx(speed * seconds, rel=1e-6)
    expected = 2 * speed / cycle_length(1.75) * seconds
    assert abs(_crossings(np.array(hips)) - expected) <= 1


def test_the_world_keeps_facing_and_stops_the_gait_at_a_pause():
    world = World.from_config(
        {
            "people": [
                {"waypoints": [[3.0, 3.0], [3.0, 4.0]], "speed": 0.5, "pause": 5.0, "loop": False}
            ]
        },
        0,
    )
    for _ in range(3 * 30):  # 2 s to walk 1 m, then the pause
        world.step(1 / 30)
    (cyl,) = world.scene().cylinders
    assert cyl.facing == pytest.approx(math.pi / 2)  # walked along +y
    assert cyl.speed == 0.0
    assert cyl.walked == pytest.approx(1.0)


def test_textures_come_from_the_seed():
    for kind in KINDS:
        a, b = modulation(kind, 64, 3), modulation(kind, 64, 3)
        assert np.array_equal(a, b)
        assert a.mean() == pytest.approx(1.0, abs=0.02)  # keeps the surface's albedo
        if kind != "plain":
            assert not np.array_equal(a, modulation(kind, 64, 4))


@mujoco_missing
def test_rendered_limbs_move_only_when_walking_and_frames_repeat():
    import dataclasses

    from fpga_robotics.sim.camera.render3d import MujocoRenderer

    renderer = MujocoRenderer(W, H, HFOV)
    base = person_scene(2.5, 0.0)
    (cyl,) = base.cylinders
    # Side on to the camera, so that the swing shows.
    side = dataclasses.replace(cyl, facing=math.pi / 2)

    def frame(walked, speed):
        c = dataclasses.replace(side, walked=walked, speed=speed)
        return renderer.render(dataclasses.replace(base, cylinders=(c,)), POSE)

    quarter = cycle_length(1.75) / 4
    standing = [frame(w, 0.0) for w in (0.0, quarter, 2 * quarter)]
    assert all(np.array_equal(standing[0], f) for f in standing[1:])
    walking = [frame(w, 0.5) for w in (quarter, 3 * quarter)]  # legs forward, then back
    changed = (walking[0] != walking[1]).any(axis=2)
    assert changed.sum() > 30
    # Only the person changes: columns within a stride's reach (0.6 m) of their centre.
    f = (W / 2) / math.tan(HFOV / 2)
    cols = np.nonzero(changed.any(axis=0))[0] + 0.5
    assert np.abs(cols - W / 2).max() <= f * 0.6 / 2.5
    # The same inputs, a new renderer: the same frame, pixel for pixel.
    again = MujocoRenderer(W, H, HFOV)
    c = dataclasses.replace(side, walked=quarter, speed=0.5)
    assert np.array_equal(again.render(dataclasses.replace(base, cylinders=(c,)), POSE), walking[0])
