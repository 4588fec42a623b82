"""Driving the target person by hand (``World.set_target_velocity``, the live teleop): the
target moves at the velocity given while its script waits, and when handed back walks its
script on from where it was left, shifted by how far it was driven (issue 16); walls and
furniture stop it, and a speed no person walks is refused."""

import math

import pytest

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.ros.controls import check_input, load_inputs
from fpga_robotics.sim.world import World
from fpga_robotics.sim.world.world import MAX_TARGET_SPEED

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
    for velocity in ((math.nan, 0.0), (1e300, 0.0), (MAX_TARGET_SPEED, 0.1)):
        with pytest.raises(ValueError, match="at most 3 m/s"):
            world.set_target_velocity(velocity)
    with pytest.raises(ValueError, match="no target"):
        World.from_config({"people": []}, seed=0).set_target_velocity((0.1, 0.0))


def test_a_speed_no_person_walks_is_a_refused_input_and_a_replay_usage_error(tmp_path):
    assert check_input("target_velocity", [0.0, -MAX_TARGET_SPEED]) == (
        "target_velocity",
        [0.0, -MAX_TARGET_SPEED],
    )
    with pytest.raises(ValueError, match="at most 3 m/s"):
        check_input("target_velocity", [1e300, 0])
    path = tmp_path / "huge.json"
    path.write_text('[{"frame": 3, "kind": "target_velocity", "value": [1e6, 0]}]')
    with pytest.raises(UsageError, match=r"input 0: target_velocity must be at most 3 m/s"):
        load_inputs(path)


def test_driven_target_stops_at_the_wall_and_slides_along_it():
    world = World.from_config({"people": [TARGET]}, seed=0)
    radius = world.config.people[0].radius
    # Within one step of the wall: a step that would go into it is not taken.
    world.set_target_velocity((2.0, 0.1))
    run(world, 5.0)  # 10 m in +x would leave the 8 m room; +y goes on along the wall
    assert target_xy(world) == pytest.approx((8.0 - radius, 5.5), abs=2.0 * DT)
    world.set_target_velocity((0.0, 1.0))
    run(world, 2.0)  # into the corner
    assert target_xy(world) == pytest.approx((8.0 - radius, 6.0 - radius), abs=2.0 * DT)


def test_driven_target_stops_at_furniture():
    box = {"name": "box", "center": [4.0, 5.0], "size": [1.0, 0.6]}  # x from 3.5
    world = World.from_config({"room": {"furniture": [box]}, "people": [TARGET]}, seed=0)
    radius = world.config.people[0].radius
    world.set_target_velocity((1.0, 0.0))
    run(world, 3.0)
    x, y = target_xy(world)
    assert y == pytest.approx(5.0)
    assert 3.5 - radius - 1.0 * DT <= x <= 3.5 - radius
