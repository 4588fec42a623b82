"""Collision episodes, contact time, impulse and fault, on hand-made contacts in a World.

Expected times come from the motor ramp (``wheel_accel_dps2``) and the people's scripted
speeds; the impulse of a stop from Newton (m v, plus the drive's push during that step).
"""

import math

import pytest

from fpga_robotics.sim.world import TURTLEBOT2, World
from fpga_robotics.sim.world.collisions import (
    EPISODE_GAP,
    FAULT_WINDOW,
    CollisionLog,
    MotionHistory,
)

DT = 1 / 200
CONTACT = 0.2 + TURTLEBOT2.body_radius  # centres of a person and the robot when they touch
RAMP = TURTLEBOT2.wheel_accel_dps2  # DPS per second


def _dps(speed):
    """Wheel DPS for a forward speed, m/s."""
    return math.degrees(speed / TURTLEBOT2.wheel_radius)


def _world(robot, people=(), room=None):
    cfg = {"robot": robot, "people": list(people)}
    if room:
        cfg["room"] = room
    return World.from_config(cfg, 0)


def _run(world, seconds, events=None):
    for _ in range(round(seconds / DT)):
        world.step(DT)
        if events is not None:
            events += [(world.time, e) for e in world.drain_events()]


def test_contacts_that_resume_within_the_gap_are_one_episode():
    log = CollisionLog(("person",))
    shape = object()
    t = 1.0
    stretches = 0.0
    for _ in range(28):  # 28 touches of 10 ms, 3 ms apart: one person leaning in
        assert log.begin("person", "p1", shape, t) is (t == 1.0)
        log.separate("person", "p1", shape, t + 0.01)
        stretches += 0.01
        t += 0.013
    assert log.episodes() == {"person": 1}
    assert log.summary(t)["person"]["contact_s"] == pytest.approx(stretches)
    # Touching again after more than the gap is a second episode.
    assert log.begin("person", "p1", shape, t - 0.003 + EPISODE_GAP + 0.01)
    assert log.episodes() == {"person": 2}
    # Another body is an episode of its own, even at the same time.
    assert log.begin("person", "p2", object(), t + EPISODE_GAP + 0.01)
    assert log.episodes() == {"person": 3}


def test_a_person_walking_steadily_into_a_parked_robot_is_one_episode_not_its_fault():
    person = {"name": "p1", "waypoints": [[5.0, 3.0], [1.0, 3.0]], "speed": 0.6, "loop": False}
    world = _world({"start": [3.0, 3.0]}, [person])
    events = []
    _run(world, 8.0, events)
    # They touch when the person has walked 2 - CONTACT, and part when the person stops
    # at the end of the path (the robot, pushed at 0.6 m/s, slides on).
    touch = (2.0 - CONTACT) / 0.6
    stop = 4.0 / 0.6
    assert [e for _, e in events] == [
        (
            "collision with person 'p1' (robot closing 0.00 m/s, person 0.60 m/s: "
            "not the robot's fault)"
        )
    ]
    assert events[0][0] == pytest.approx(touch, abs=DT)
    summary = world.collision_summary()
    assert summary["person"]["episodes"] == world.collision_counts()["person"] == 1
    assert summary["person"]["contact_s"] == pytest.approx(stop - touch, abs=DT)
    assert world.at_fault_collisions() == 0


def test_a_creeping_robot_hit_by_a_walking_person_is_not_at_fault():
    # The robot creeps towards the person at 0.06 m/s (above AT_FAULT_SPEED), the person
    # walks into it at 0.6 m/s: the person closed the gap.
    person = {"name": "p1", "waypoints": [[5.0, 3.0], [1.0, 3.0]], "speed": 0.6, "loop": False}
    world = _world({"start": [3.0, 3.0]}, [person])
    world.set_wheel_dps(_dps(0.06), _dps(0.06))
    events = []
    _run(world, 3.0, events)
    assert [e for _, e in events] == [
        (
            "collision with person 'p1' (robot closing 0.06 m/s, person 0.60 m/s: "
            "not the robot's fault)"
        )
    ]
    assert world.at_fault_collisions() == 0


@pytest.mark.parametrize("h", [1 / 240, 0.0005, 0.0002])
def test_fault_velocities_average_over_the_window_at_any_physics_step(h):
    # A person walks at 1 m/s until 0.2 s, then stands: over the 0.1 s before 0.25 s they
    # moved 0.05 m, 0.5 m/s on average, whatever the step the positions were recorded at.
    history = MotionHistory()
    n = round(0.25 / h)
    for k in range(n):
        t = k * h
        history.record(t, (0.0, 0.0), (0.0, 0.0), ((min(t, 0.2), 0.0),))
    robot_v, driven_v, (person_v,) = history.mean_velocities(
        n * h, (0.0, 0.0), (0.0, 0.0), ((0.2, 0.0),)
    )
    assert robot_v == driven_v == (0.0, 0.0)
    assert person_v[0] == pytest.approx(0.05 / FAULT_WINDOW, abs=h / FAULT_WINDOW)


@pytest.mark.parametrize("dt", [1 / 240, 0.0005])
def test_the_fault_of_a_touch_does_not_depend_on_the_physics_step(dt):
    # The robot creeps at 0.06 m/s; the person walks at 0.6 m/s towards it and stops about
    # 80 ms before the touch: over the last 0.1 s they still closed faster than the robot.
    cfg = {
        "room": {"width": 8, "depth": 6},
        "robot": {"start": [1, 3]},
        "people": [{"waypoints": [[3, 3], [1.527, 3]], "speed": 0.6, "loop": False}],
    }
    world = World.from_config(cfg, 0)
    world.set_wheel_dps(_dps(0.06), _dps(0.06))
    events = []
    while not events:
        world.step(dt)
        events = world.drain_events()
    assert world.time == pytest.approx(2.53, abs=0.01)
    (event,) = events
    assert event.endswith("not the robot's fault)")
    # The person's 0.1 s average: 0.6 m/s for about 20 ms of it.
    person = float(event.split("person ")[-1].split(" m/s")[0])
    assert 0.1 <= person <= 0.2
    assert world.at_fault_collisions() == 0


def test_a_robot_shoved_into_a_standing_person_is_not_at_fault_nor_shot_out():
    # The robot is parked (wheels at 0) between green, standing 0.65 m ahead, and blue, who
    # walks into it from behind at 0.8 m/s and stops 0.65 m from green: blue shoves it into
    # green (it drove nothing: not its fault), then squeezes it out sideways, at no more
    # than blue's 0.8 m/s (rigid people would shoot it out at several m/s, into the wall).
    green = {"name": "green", "waypoints": [[3.65, 3.0]]}
    blue = {"name": "blue", "waypoints": [[1.0, 3.05], [3.0, 3.05]], "speed": 0.8, "loop": False}
    world = _world({"start": [3.0, 3.0]}, [green, blue])
    events, fastest = [], 0.0
    for _ in range(round(6.0 / DT)):
        world.step(DT)
        events += world.drain_events()
        fastest = max(fastest, world.robot_body.velocity.length)
    assert [e.split(" (")[0] for e in events] == [
        "collision with person 'blue'",
        "collision with person 'green'",
    ]
    assert world.at_fault_collisions() == 0
    assert fastest <= 0.8 + 1e-9
    assert world.driven_position() == (3.0, 3.0)


def test_only_the_people_touching_the_robot_bound_how_fast_a_squeeze_moves_it():
    # A person walks at 0.5 m/s almost head-on into a parked robot against the wall (1 cm off
    # its centre line) and squeezes it out sideways; a runner at 5 m/s crosses the far side
    # of the room, never near it. The body moves at most at the squeezer's 0.5 m/s, and the
    # runner changes nothing (before, the fastest person anywhere set the bound: 5 m/s, and
    # the robot shot across the room).
    squeezer = {
        "name": "squeezer",
        "waypoints": [[2.01, 2.0], [2.01, 0.3]],
        "speed": 0.5,
        "loop": False,
        "radius": 0.3,
    }
    runner = {
        "name": "runner",
        "target": False,
        "waypoints": [[1.0, 5.5], [7.0, 5.5]],
        "speed": 5.0,
        "pause": 0.0,
    }
    ends = []
    for people in ([squeezer], [squeezer, runner]):
        world = _world({"start": [2.0, 0.18]}, people)
        fastest = 0.0
        for _ in range(round(6.0 / DT)):
            world.step(DT)
            fastest = max(fastest, world.robot_body.velocity.length)
        assert 0.4 < fastest <= 0.5 + 1e-9  # it was pushed, at no more than 0.5 m/s
        ends.append(world.robot_pose())
    assert ends[0] == pytest.approx(ends[1], abs=1e-9)
    assert math.dist(ends[0][:2], (2.0, 0.18)) > 0.2  # squeezed out along the wall


def test_people_squeezing_past_a_parked_robot_spin_it_no_faster_than_its_rim_slides():
    # Two people pass a parked GoPiGo3 on either side in opposite directions at 1 m/s, their
    # paths 0.5 m apart where the robot and they need 0.62 m: they squeeze it. It moves at
    # most at 1 m/s (the fastest person's speed), so its rim slides past what touches it at
    # most 1 + 1 m/s and friction spins it at most at 2 m/s / body_radius (18.2 rad/s; the
    # rigid people's solver spun it at 26 rad/s), and the traction stops the turn afterwards.
    left = {"name": "a", "waypoints": [[0.5, 2.25], [5.5, 2.25]], "speed": 1.0, "loop": False}
    right = {"name": "b", "waypoints": [[5.5, 1.75], [0.5, 1.75]], "speed": 1.0, "loop": False}
    world = _world(
        {"model": "gopigo3", "start": [3.0, 2.0]}, [left, right], {"width": 6, "depth": 4}
    )
    fastest = 0.0
    for _ in range(round(3.0 / DT)):
        world.step(DT)
        fastest = max(fastest, abs(world.robot_velocity()[1]))
    assert fastest > 5.0  # they did spin it
    assert fastest <= 2.0 / world.robot_spec.body_radius + 1e-9
    _run(world, 3.0)  # they are gone; the wheels stand
    assert world.robot_velocity()[1] == pytest.approx(0.0, abs=1e-6)


def test_the_driven_position_follows_a_robot_driving_unhindered():
    # Ramping up to 300 DPS, turning, ramping down: nothing but its wheels moves it.
    world = _world({"start": [2.0, 3.0]})
    for left, right in [(300, 300), (300, 200), (0, 0)]:
        world.set_wheel_dps(left, right)
        _run(world, 1.5)
    x, y, _ = world.robot_pose()
    assert math.dist(world.driven_position(), (x, y)) < 0.002
    assert math.dist((x, y), (2.0, 3.0)) > 0.4


def _touch_time(dps, distance):
    """When a robot starting still, commanded ``dps``, has covered ``distance``, s."""
    v = TURTLEBOT2.wheel_radius * math.radians(dps)
    ramp = dps / RAMP
    return ramp + (distance - v * ramp / 2) / v


def test_the_robot_driving_into_a_standing_person_is_one_episode_and_its_fault():
    person = {"name": "bob", "waypoints": [[3.0, 3.0]]}
    world = _world({"start": [2.0, 3.0]}, [person])
    world.set_wheel_dps(300, 300)
    events = []
    _run(world, 6.0, events)  # it keeps pushing against the person to the end
    touch = _touch_time(300, 1.0 - CONTACT)
    assert [e for _, e in events] == [
        ("collision with person 'bob' (robot closing 0.18 m/s, person 0.00 m/s: the robot's fault)")
    ]
    assert events[0][0] == pytest.approx(touch, abs=DT)
    summary = world.collision_summary()["person"]
    assert summary["episodes"] == 1 and world.at_fault_collisions() == 1
    # Still touching at the end: the contact counts up to now.
    assert summary["contact_s"] == pytest.approx(6.0 - touch, abs=DT)


def test_two_bumps_two_seconds_apart_are_two_episodes_and_a_quick_rebound_is_one():
    person = {"name": "bob", "waypoints": [[3.0, 3.0]]}
    world = _world({"start": [2.0, 3.0]}, [person])
    world.set_wheel_dps(300, 300)
    events = []
    _run(world, 4.0, events)  # touches at about 3.5 s
    world.set_wheel_dps(-300, -300)
    _run(world, 0.25, events)  # parts after the wheels turn round (0.18 s), backs off
    assert 3.0 - world.robot_pose()[0] > CONTACT  # the contact has broken
    world.set_wheel_dps(300, 300)
    _run(world, 1.0, events)  # back within a few tenths of a second: the same episode
    assert world.collision_counts()["person"] == 1
    world.set_wheel_dps(-300, -300)
    _run(world, 1.5, events)
    world.set_wheel_dps(300, 300)
    _run(world, 3.0, events)
    times = [t for t, e in events]
    assert len(times) == 2 and times[1] - times[0] > 2.0
    assert world.collision_counts()["person"] == 2
    assert world.at_fault_collisions() == 2


def test_a_wall_hit_gives_its_contact_time_and_impulse():
    world = _world({"start": [6.5, 3.0]})
    world.set_wheel_dps(1000, 1000)
    _run(world, 5.0)
    v = TURTLEBOT2.wheel_radius * math.radians(1000)
    touch = _touch_time(1000, 8.0 - TURTLEBOT2.body_radius - 6.5)
    wall = world.collision_summary()["wall"]
    assert wall["episodes"] == 1
    assert wall["contact_s"] == pytest.approx(5.0 - touch, abs=DT)
    # Stopping m at v in one step, while the drive pushes with its traction for that step.
    expected = TURTLEBOT2.mass * v + TURTLEBOT2.traction_force * DT
    assert wall["max_impulse_ns"] == pytest.approx(expected, rel=0.02)
    assert world.collision_summary()["person"] == {
        "episodes": 0,
        "contact_s": 0.0,
        "max_impulse_ns": 0.0,
    }
