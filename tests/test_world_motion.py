"""The robot in the physics world: straight runs, turns, ramps, traction, walls, people.

Expected values come from the motor model (a wheel ramps at ``wheel_accel_dps2`` to its
target) and Newton (a traction-limited body accelerates at ``traction_force / mass``).
Tolerances are a few physics steps' worth of motion, since the motors and the body move in
steps of ``DT``.
"""

import math

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from fpga_robotics.sim.world import TURTLEBOT2, World

DT = 1 / 200
EMPTY = {"people": []}


def run(world, seconds, dt=DT):
    for _ in range(round(seconds / dt)):
        world.step(dt)


def empty_world(robot=None, room=None, people=()):
    cfg = {"people": list(people)}
    if robot:
        cfg["robot"] = robot
    if room:
        cfg["room"] = room
    return World.from_config(cfg, seed=0)


def test_straight_run_covers_the_expected_distance():
    world = empty_world({"start": [1.0, 3.0]})
    world.set_wheel_dps(360, 360)
    seconds = 5.0
    run(world, seconds)
    v = 0.035 * 2 * math.pi
    ramp = 360 / TURTLEBOT2.wheel_accel_dps2  # s to reach 360 DPS
    # The ramp covers half the distance a full-speed start would: x = v (T - ramp / 2).
    expected = 1.0 + v * (seconds - ramp / 2)
    x, y, heading = world.robot_pose()
    assert x == pytest.approx(expected, abs=2 * v * DT)
    assert y == pytest.approx(3.0, abs=1e-6)
    assert heading == pytest.approx(0.0, abs=1e-6)
    assert world.robot_velocity() == pytest.approx((v, 0.0), abs=1e-6)
    assert world.collision_counts() == {"person": 0, "wall": 0, "furniture": 0}


def test_heading_sets_the_direction_of_travel():
    world = empty_world({"start": [4.0, 1.0], "heading_deg": 90})
    world.set_wheel_dps(360, 360)
    run(world, 3.0)
    x, y, _ = world.robot_pose()
    assert x == pytest.approx(4.0, abs=1e-6)
    assert y - 1.0 == pytest.approx(0.035 * 2 * math.pi * (3.0 - 360 / 1637 / 2), abs=0.003)


def test_turning_in_place_rotates_by_the_expected_angle():
    world = empty_world({"start": [4.0, 3.0]})
    world.set_wheel_dps(-90, 90)
    seconds = 3.0
    run(world, seconds)
    w = 0.035 * math.pi / 0.230
    ramp = 90 / TURTLEBOT2.wheel_accel_dps2
    x, y, heading = world.robot_pose()
    assert heading == pytest.approx(w * (seconds - ramp / 2), abs=2 * w * DT)
    assert (x, y) == pytest.approx((4.0, 3.0), abs=1e-6)
    assert world.robot_velocity()[1] == pytest.approx(w, rel=1e-6)


def time_to_reach(world, fraction, target_v, limit=5.0):
    """First time the measured forward speed reaches ``fraction * target_v``."""
    while world.time < limit:
        world.step(DT)
        if world.robot_velocity()[0] >= fraction * target_v:
            return world.time
    raise AssertionError("never reached the speed")


def test_acceleration_limit_gives_the_ramp_time():
    world = empty_world({"start": [1.0, 3.0]})
    world.set_wheel_dps(720, 720)
    v = 0.035 * 4 * math.pi
    # Nominal TurtleBot2: traction is ample, so the motor ramp sets the pace.
    expected = 720 / TURTLEBOT2.wheel_accel_dps2
    assert time_to_reach(world, 0.999, v) == pytest.approx(expected, abs=2 * DT)


def test_slower_ramp_from_config():
    world = empty_world({"start": [1.0, 3.0], "wheel_accel_dps2": 400})
    world.set_wheel_dps(720, 720)
    assert time_to_reach(world, 0.999, 0.035 * 4 * math.pi) == pytest.approx(1.8, abs=2 * DT)


@pytest.mark.parametrize(
    "robot, force, mass",
    [
        ({"mass": 30.0}, TURTLEBOT2.traction_force, 30.0),  # heavier robot, same motors
        ({"traction_force": 3.0}, 3.0, TURTLEBOT2.mass),  # weaker motors
    ],
)
def test_heavier_robot_or_weaker_traction_accelerates_slower(robot, force, mass):
    nominal = empty_world({"start": [1.0, 3.0]})
    slow = empty_world({"start": [1.0, 3.0], **robot})
    v = 0.035 * 4 * math.pi
    for world in (nominal, slow):
        world.set_wheel_dps(720, 720)
    t_nominal = time_to_reach(nominal, 0.999, v)
    t_slow = time_to_reach(slow, 0.999, v)
    # Traction-limited: the body accelerates at F / m the whole way.
    assert force / mass < TURTLEBOT2.motor_accel
    assert t_slow == pytest.approx(v * mass / force, abs=2 * DT)
    assert t_slow > 1.5 * t_nominal


def test_top_speed_is_clamped_to_the_motors_maximum():
    world = empty_world({"model": "gopigo3", "start": [0.5, 3.0]})
    world.set_wheel_dps(2000, 2000)
    run(world, 2.0)
    assert world.robot_velocity()[0] == pytest.approx(0.03325 * 512 * math.pi / 180, rel=1e-6)
    assert world.commanded_twist()[0] == pytest.approx(0.03325 * 2000 * math.pi / 180)


def test_robot_cannot_drive_through_a_wall():
    world = empty_world({"start": [6.5, 3.0]})
    world.set_wheel_dps(1000, 1000)
    limit = 8.0 - TURTLEBOT2.body_radius
    furthest = 0.0
    for _ in range(round(5.0 / DT)):
        world.step(DT)
        furthest = max(furthest, world.robot_pose()[0])
    x, _, _ = world.robot_pose()
    assert x == pytest.approx(limit, abs=0.005)
    assert furthest < limit + 0.005
    assert abs(world.robot_velocity()[0]) < 1e-3
    assert world.collision_counts() == {"person": 0, "wall": 1, "furniture": 0}
    assert world.drain_events() == ["collision with wall"]
    assert world.drain_events() == []


def test_robot_stops_at_furniture_and_names_it():
    room = {"furniture": [{"name": "cabinet", "center": [5.0, 3.0], "size": [1.0, 2.0]}]}
    world = empty_world({"start": [3.0, 3.0]}, room)
    world.set_wheel_dps(800, 800)
    run(world, 5.0)
    assert world.robot_pose()[0] == pytest.approx(4.5 - TURTLEBOT2.body_radius, abs=0.005)
    assert world.collision_counts()["furniture"] == 1
    assert world.drain_events() == ["collision with furniture 'cabinet'"]


def test_driving_into_a_standing_person_is_a_collision_and_does_not_move_them():
    person = {"name": "bob", "waypoints": [[4.0, 3.0]]}
    world = empty_world({"start": [2.0, 3.0]}, people=[person])
    world.set_wheel_dps(1000, 1000)
    run(world, 5.0)
    assert world.robot_pose()[0] == pytest.approx(4.0 - 0.2 - TURTLEBOT2.body_radius, abs=0.005)
    (state,) = world.people_states()
    assert (state.x, state.y) == pytest.approx((4.0, 3.0), abs=1e-9)
    assert world.collision_counts() == {"person": 1, "wall": 0, "furniture": 0}
    # 1000 DPS: 0.035 m * 1000 * pi / 180 = 0.61 m/s towards a person standing still.
    assert world.drain_events() == [
        ("collision with person 'bob' (robot closing 0.61 m/s, person 0.00 m/s: the robot's fault)")
    ]


def test_a_walking_person_pushes_the_robot_and_keeps_to_their_script():
    person = {"name": "walker", "waypoints": [[6.0, 3.0], [1.0, 3.0]], "speed": 0.5, "loop": False}
    world = empty_world({"start": [3.5, 3.0]}, people=[person])
    run(world, 2.0)  # 1 m walked, nothing touched yet (gap 2.5 - 0.377 m)
    assert world.collision_counts()["person"] == 0
    for _ in range(round(4.0 / DT)):
        world.step(DT)
        (state,) = world.people_states()
        assert state.x == pytest.approx(6.0 - 0.5 * world.time, abs=1e-6)
        assert state.y == pytest.approx(3.0, abs=1e-9)
    assert world.collision_counts()["person"] == 1
    # The robot was shoved ahead of the person, staying in contact.
    assert world.robot_pose()[0] < 3.5 - 0.5
    assert world.robot_pose()[0] == pytest.approx(3.0 - 0.2 - TURTLEBOT2.body_radius, abs=0.01)


CONTACT = 0.2 + TURTLEBOT2.body_radius  # centres of a person and the robot when they touch


def test_a_yielding_person_waits_for_the_robot_and_then_keeps_to_their_script():
    person = {
        "name": "walker",
        "waypoints": [[6.0, 3.0], [1.0, 3.0]],
        "speed": 0.5,
        "loop": False,
        "yield_gap": 0.3,
    }
    world = empty_world({"start": [3.5, 3.0]}, people=[person])
    run(world, 6.0)  # they would reach the robot after (6 - 3.5 - 0.377) / 0.5 = 4.2 s
    (state,) = world.people_states()
    # Waiting where one more step (0.5 m/s for 5 ms) would come closer than the gap.
    assert 3.5 + CONTACT + 0.3 <= state.x < 3.5 + CONTACT + 0.3 + 0.5 * DT
    assert world.collision_counts()["person"] == 0
    # The robot backs away at 0.2 m/s: they follow at the gap, never closer.
    world.set_wheel_dps(-0.2 / 0.035 / (math.pi / 180), -0.2 / 0.035 / (math.pi / 180))
    for _ in range(round(4.0 / DT)):
        world.step(DT)
        (state,) = world.people_states()
        gap = math.hypot(state.x - world.robot_pose()[0], state.y - 3.0) - CONTACT
        assert gap > 0.3 - 0.5 * DT
    assert world.collision_counts()["person"] == 0
    # The robot leaves the path: they walk on, their script delayed by the wait.
    world.set_wheel_dps(0, 0)
    world.robot_body.position = (3.0, 1.0)
    run(world, 8.0)
    (state,) = world.people_states()
    assert (state.x, state.y) == pytest.approx((1.0, 3.0))


def test_a_yielding_person_still_walks_past_the_robot():
    # Their path passes 0.75 m from the robot's centre, 0.37 m between the bodies: never
    # closer than the gap (0.3 m), so they never wait.
    person = {"waypoints": [[6.0, 3.5], [1.0, 3.5]], "speed": 0.5, "loop": False, "yield_gap": 0.3}
    world = empty_world({"start": [3.5, 2.75]}, people=[person])
    for _ in range(round(10.0 / DT)):
        world.step(DT)
        (state,) = world.people_states()
        assert state.x == pytest.approx(max(1.0, 6.0 - 0.5 * world.time), abs=1e-6)
    assert world.collision_counts()["person"] == 0


def test_same_seed_same_trajectory_different_seed_different_people():
    people = [
        {
            "waypoints": [[3, 3], [6, 4], [6, 2]],
            "speed": 0.6,
            "speed_jitter": 0.3,
            "pause": [0.5, 1.0, 0.2],
        }
    ]

    def trajectory(seed):
        world = World.from_config({"people": people, "robot": {"start": [1.0, 3.0]}}, seed)
        out = []
        for k in range(1500):
            if k % 7 == 0:  # a changing command, like the design's
                world.set_wheel_dps(200 + 30 * math.sin(k / 50), 200 + 30 * math.cos(k / 40))
            world.step(DT)
            out.append(world.robot_pose() + world.target_position())
        return out

    assert trajectory(5) == trajectory(5)
    assert trajectory(5) != trajectory(6)


def test_step_splits_long_steps():
    a = empty_world({"start": [1.0, 3.0]})
    b = empty_world({"start": [1.0, 3.0]})
    for world in (a, b):
        world.set_wheel_dps(300, 330)
    run(a, 1.0, dt=0.05)  # split into five sub-steps of MAX_SUBSTEP = 10 ms
    run(b, 1.0, dt=0.01)
    assert a.time == pytest.approx(1.0)
    assert a.robot_pose() == pytest.approx(b.robot_pose(), abs=1e-9)
    with pytest.raises(ValueError, match="dt"):
        a.step(0.0)


@settings(max_examples=15, deadline=None)
@given(
    st.lists(st.tuples(st.integers(-1500, 1500), st.integers(-1500, 1500)), min_size=5, max_size=5),
    st.sampled_from(["turtlebot2", "gopigo3"]),
)
# Once found with the person's path ending 0.5 m from a wall: the scripted person pinned the
# robot against the wall and pushed it 2 cm into it (people do not yield; docs/scenarios.md).
@example([(-764, 971), (0, 7), (1028, 449), (0, 352), (0, 0)], "turtlebot2")
def test_no_command_sequence_gets_the_robot_out_of_the_room(commands, model):
    # The person walks where it can bump into the robot but never pin it against a wall or
    # the box (at least a robot's diameter away from both).
    room = {
        "width": 3.0,
        "depth": 2.5,
        "furniture": [{"name": "box", "center": [2.2, 1.2], "size": [0.5, 0.5]}],
    }
    world = World.from_config(
        {
            "room": room,
            "robot": {"model": model, "start": [0.8, 1.2]},
            "people": [{"waypoints": [[1.2, 0.8], [1.2, 1.7]]}],
        },
        seed=1,
    )
    r = world.robot_spec.body_radius
    for left, right in commands:
        world.set_wheel_dps(left, right)
        for _ in range(300):
            world.step(DT)
            x, y, _ = world.robot_pose()
            assert r - 0.02 < x < 3.0 - r + 0.02
            assert r - 0.02 < y < 2.5 - r + 0.02
            # never into the box: centre-to-box distance at least the body radius
            gap = math.hypot(max(abs(x - 2.2) - 0.25, 0.0), max(abs(y - 1.2) - 0.25, 0.0))
            assert gap > r - 0.02
