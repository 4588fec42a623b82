"""Driving the target person by hand (``World.set_target_velocity``, the live teleop): the
target moves at the velocity given while its script waits, and when handed back walks its
script on from where it was left, shifted by how far it was driven (issue 16)."""

import math

import pytest

from fpga_robotics.sim.world import World

DT = 1 / 200
# The script: wait 0.5 s at (2, 5), then walk +x at 0.8 m/s to (6, 5).
TARGET = {
    "name": "target",
    "target": True,
    "waypoints": [[2, 5], [6, 5]],
    "speed": 0.8,
    "start_delay": 0.5,
    "loop": False,
}
# Far from the robot's default start, so nothing bumps into anything.
WALKER = {"name": "walker", "waypoints": [[1, 1], [1, 2]], "speed": 0.5, "loop": False}


def run(world, seconds):
    for _ in range(round(seconds / DT)):
        world.step(DT)


def target_xy(world):
    return world.target_position()


def test_driven_target_moves_at_the_velocity_and_resumes_its_script_shifted():
    world = World.from_config({"people": [TARGET, WALKER]}, seed=0)
    run(world, 1.5)  # walked 1.0 s at 0.8 m/s
    assert target_xy(world) == pytest.approx((2.8, 5.0), abs=1e-9)
    world.set_target_velocity((0.0, -0.4))
    run(world, 1.0)  # driven 0.4 m in -y; the script waits
    assert target_xy(world) == pytest.approx((2.8, 4.6), abs=1e-9)
    world.set_target_velocity((0.0, 0.0))
    run(world, 0.5)  # standing
    assert target_xy(world) == pytest.approx((2.8, 4.6), abs=1e-9)
    world.set_target_velocity(None)
    run(world, 1.0)  # the script goes on: +x at 0.8 m/s, 0.4 m below its path
    assert target_xy(world) == pytest.approx((3.6, 4.6), abs=1e-9)
    # The other person never waited: 3.5 s at 0.5 m/s, 1 m long path, ended at (1, 2).
    walker = next(p for p in world.people_states() if p.name == "walker")
    assert (walker.x, walker.y) == pytest.approx((1.0, 2.0))


def test_driven_target_is_seen_by_the_camera_where_it_is():
    world = World.from_config({"people": [TARGET]}, seed=0)
    world.set_target_velocity((0.3, 0.2))
    run(world, 2.0)
    x, y = target_xy(world)
    assert (x, y) == pytest.approx((2.6, 5.4), abs=1e-9)
    cyl = world.scene().cylinders[0]
    assert (cyl.x, cyl.y) == pytest.approx((x, y))


def test_bad_target_velocity_and_no_target():
    world = World.from_config({"people": [TARGET]}, seed=0)
    with pytest.raises(ValueError, match="finite"):
        world.set_target_velocity((math.nan, 0.0))
    with pytest.raises(ValueError, match="no target"):
        World.from_config({"people": []}, seed=0).set_target_velocity((0.1, 0.0))
