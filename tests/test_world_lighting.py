"""Lighting keyframes: linear and step interpolation, and the scene's lighting over time."""

import pytest

from fpga_robotics.sim.camera.scene import Lighting
from fpga_robotics.sim.world import World, parse_world_config
from fpga_robotics.sim.world.lighting import LightingSchedule


def schedule(**lighting):
    return LightingSchedule(parse_world_config({"lighting": lighting}).lighting)


def test_constant_without_keyframes():
    s = schedule(ambient=0.3, intensity=0.9, direction=[0, 1, -1])
    assert s.at(0.0) == Lighting(ambient=0.3, intensity=0.9, direction=(0.0, 1.0, -1.0))
    assert s.at(1e4) == s.at(0.0)


def test_linear_keyframes_interpolate_and_hold_at_the_ends():
    s = schedule(keyframes=[[2, 0.2, 0.0], [12, 0.8, 1.0], [14, 0.4, 1.0]])
    assert s.levels(0.0) == (0.2, 0.0)  # before the first: the first
    assert s.levels(2.0) == (0.2, 0.0)
    assert s.levels(7.0) == pytest.approx((0.5, 0.5))
    assert s.levels(9.5) == pytest.approx((0.65, 0.75))
    assert s.levels(13.0) == pytest.approx((0.6, 1.0))
    assert s.levels(99.0) == (0.4, 1.0)  # after the last: the last


def test_step_keyframes_hold_until_the_next():
    s = schedule(keyframes=[[0, 0.2, 0.1], [10, 0.8, 1.0]], interpolation="step")
    assert s.levels(9.999) == (0.2, 0.1)
    assert s.levels(10.0) == (0.8, 1.0)


def test_two_keyframes_at_one_time_make_a_jump():
    s = schedule(keyframes=[[0, 0.7, 0.5], [5, 0.7, 0.5], [5, 0.1, 0.0]])
    assert s.levels(4.99) == pytest.approx((0.7, 0.5))
    assert s.levels(5.0) == (0.1, 0.0)


def test_scene_lighting_follows_world_time():
    cfg = {"people": [], "lighting": {"keyframes": [[0, 0.8, 0.6], [4, 0.2, 0.2]]}}
    world = World.from_config(cfg, seed=0)
    assert world.scene().lighting.ambient == pytest.approx(0.8)
    for _ in range(3 * 200):
        world.step(1 / 200)
    light = world.scene().lighting
    assert (light.ambient, light.intensity) == pytest.approx((0.35, 0.3))
    assert light.direction == (1.0, 0.5, -1.0)


def test_a_step_keyframe_acts_at_a_frame_whose_clock_reads_just_below_it():
    # 888 steps of 1/240 s add up to 3.6999999999999997 s, the clock of the frame at 3.7 s
    # (30 fps): the keyframe at 3.7 s is in force there, as a colour change at 3.7 s is.
    cfg = {
        "people": [],
        "lighting": {"keyframes": [[0, 0.6, 0.5], [3.7, 0.9, 0.2]], "interpolation": "step"},
    }
    world = World.from_config(cfg, seed=0)
    for _ in range(888):
        world.step(1 / 240)
    assert world.time < 3.7 and world.time == pytest.approx(3.7)
    light = world.scene().lighting
    assert (light.ambient, light.intensity) == (0.9, 0.2)
