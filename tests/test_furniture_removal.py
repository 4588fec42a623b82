"""Furniture with present_until: it leaves the physics, the camera's scene, the map and the
ultrasound's beam at that time, with one event; collision counts stay as they were."""

import pytest

from fpga_robotics.sim.world import World, WorldConfigError
from fpga_robotics.sim.world.ultrasound import HCSR04Params, range_to

BOX = {
    "name": "crate",
    "center": [2.0, 3.0],
    "size": [0.4, 0.4],
    "height": 0.5,
    "present_until": 1.5,
}


def _world(start=(1.0, 3.0)):
    return World.from_config(
        {
            "room": {
                "width": 5.0,
                "depth": 6.0,
                "furniture": [BOX, {"name": "stays", "center": [4.0, 1.0]}],
            },
            "robot": {"start": list(start)},
            "people": [],
        }
    )


def test_the_box_leaves_at_its_time_with_one_event():
    world = _world()
    walls = len(world.scene().walls)
    sensor = (1.2, 3.0, 0.0, 0.1, HCSR04Params(noise_std=0.0))
    assert range_to(world, *sensor) == pytest.approx(0.6)  # the crate's face at x = 1.8
    events = []
    while world.time < 1.5 - 1e-9:
        assert len(world.scene().walls) == walls and len(world.world_map().obstacles) == 2
        world.step(0.1)
        events += world.drain_events()
    assert world.time == pytest.approx(1.5)
    assert events == ["furniture 'crate' removed"]
    assert len(world.scene().walls) == walls - 4
    assert {w.part for w in world.scene().walls} == {"", "stays"}
    assert len(world.world_map().obstacles) == 1
    assert [f.name for f in world.present_furniture()] == ["stays"]
    assert range_to(world, *sensor) == pytest.approx(3.8)  # the wall behind it
    world.step(0.1)
    assert world.drain_events() == []


def test_the_box_leaves_at_a_frame_whose_clock_reads_just_below_its_time():
    # 888 steps of 1/240 s add up to 3.6999999999999997 s: the frame at 3.7 s has no box.
    world = World.from_config(
        {"room": {"furniture": [dict(BOX, present_until=3.7)]}, "robot": {"start": [1.0, 3.0]}}
    )
    for _ in range(887):
        world.step(1 / 240)
    assert world.drain_events() == [] and len(world.present_furniture()) == 1
    world.step(1 / 240)
    assert world.time < 3.7
    assert world.drain_events() == ["furniture 'crate' removed"]
    assert world.present_furniture() == []


def test_the_robot_drives_through_where_the_box_was_and_counts_stay():
    world = _world(start=[1.4, 3.0])
    world.set_wheel_dps(400, 400)
    for _ in range(150):  # 1.5 s: into the crate and held there
        world.step(0.01)
    x_blocked = world.robot_pose()[0]
    counts = world.collision_counts()
    assert counts["furniture"] == 1 and world.furniture_contacts("crate") == 1
    assert world.furniture_contacts("stays") == 0
    assert x_blocked < 1.8 - world.robot_spec.body_radius + 0.01
    for _ in range(100):
        world.step(0.01)
    assert world.robot_pose()[0] > x_blocked + 0.1  # the way is free
    assert world.collision_counts() == counts
    with pytest.raises(ValueError, match="no furniture named 'nope'"):
        world.furniture_contacts("nope")


def test_present_until_is_validated():
    with pytest.raises(
        WorldConfigError,
        match=r"room\.furniture\[0\]\.present_until must be "
        r"> 0, got -1",
    ):
        World.from_config({"room": {"furniture": [dict(BOX, present_until=-1)]}})
    with pytest.raises(WorldConfigError, match=r"present_until"):
        World.from_config({"room": {"furniture": [dict(BOX, present_until="soon")]}})
