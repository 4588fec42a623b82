"""Scripted people: waypoints, speeds, pauses, start delay, loops, speed jitter."""

import math

import numpy as np
import pytest

from fpga_robotics.sim.world import World, parse_world_config
from fpga_robotics.sim.world.people import PersonPath


def path(person, seed=0):
    cfg = parse_world_config({"people": [person]})
    return PersonPath(cfg.people[0], np.random.default_rng(seed))


def test_one_way_walk_with_start_delay():
    p = path({"waypoints": [[1, 1], [3, 1]], "speed": 0.5, "start_delay": 1.0, "loop": False})
    assert p.position(0.0) == (1, 1)
    assert p.position(0.9) == (1, 1)
    assert p.position(3.0) == pytest.approx((2.0, 1.0))  # 2 s at 0.5 m/s after the delay
    assert p.position(5.0) == pytest.approx((3.0, 1.0))
    assert p.position(100.0) == pytest.approx((3.0, 1.0))  # stays at the last waypoint


def test_loop_with_pauses_per_waypoint():
    p = path({"waypoints": [[1, 1], [3, 1], [3, 2]], "speed": 1.0, "pause": [0.5, 1.0, 1.5]})
    diag = math.hypot(2, 1)
    # Legs: W0->W1 0..2 s, pause 1 s, W1->W2 3..4, pause 1.5 s, W2->W0 5.5..5.5+diag,
    # pause 0.5 s, then round again.
    expected = {
        1.0: (2.0, 1.0),
        2.5: (3.0, 1.0),
        3.5: (3.0, 1.5),
        5.0: (3.0, 2.0),
        5.5 + diag / 2: (2.0, 1.5),
        5.5 + diag + 0.25: (1.0, 1.0),
        6.0 + diag + 1.0: (2.0, 1.0),  # second lap
    }
    for t, where in expected.items():
        assert p.position(t) == pytest.approx(where), t
    # Positions may be asked out of order (e.g. a fresh query from the start).
    assert p.position(1.0) == pytest.approx((2.0, 1.0))


def test_world_moves_people_along_their_script_at_their_speed():
    person = {
        "name": "walker",
        "waypoints": [[2, 5], [6, 5]],
        "speed": 0.8,
        "pause": 2.0,
        "start_delay": 0.5,
    }
    world = World.from_config({"people": [person]}, seed=0)
    samples = {}
    for _ in range(round(14.0 * 200)):
        world.step(1 / 200)
        samples[round(world.time * 200)] = world.people_states()[0]

    def at(t):
        s = samples[round(t * 200)]
        return s.x, s.y

    assert at(0.5) == pytest.approx((2.0, 5.0))
    assert at(0.5 + 2.5) == pytest.approx((4.0, 5.0), abs=1e-9)  # 2 m at 0.8 m/s
    assert at(5.5) == pytest.approx((6.0, 5.0), abs=1e-9)  # arrives after 5 s
    assert at(7.4) == pytest.approx((6.0, 5.0), abs=1e-9)  # pauses 2 s ...
    assert at(7.5 + 1.25) == pytest.approx((5.0, 5.0), abs=1e-9)  # ... then walks back
    assert at(12.5) == pytest.approx((2.0, 5.0), abs=1e-9)
    # Speed measured between two samples while walking.
    (x0, _), (x1, _) = at(1.0), at(2.0)
    assert x1 - x0 == pytest.approx(0.8, abs=1e-9)


def test_speed_jitter_stays_in_bounds_and_is_seeded():
    person = {"waypoints": [[1, 1], [5, 1]], "speed": 1.0, "speed_jitter": 0.25, "pause": 0}

    def leg_durations(seed):
        p = path(person, seed)
        p.position(200.0)  # generates every leg up to 200 s
        return [t1 - t0 for t0, t1, *_ in p.segments[1:] if t1 > t0]

    durations = leg_durations(3)
    assert len(durations) > 40
    assert all(4 / 1.25 <= d <= 4 / 0.75 for d in durations)
    assert len(set(durations)) > 1
    assert durations == leg_durations(3)
    assert durations != leg_durations(4)


def test_default_world_has_a_red_shirted_target_walking_a_loop_with_pauses():
    world = World.from_config({}, seed=0)
    (target,) = world.people_states()
    assert target.is_target and target.name == "target"
    assert world.target_position() == (4.0, 3.0)
    cfg = world.config.people[0]
    assert cfg.loop and min(cfg.pauses) > 0 and len(cfg.waypoints) >= 3
    assert cfg.shirt_color == (0.85, 0.1, 0.1)
    positions = set()
    for _ in range(60 * 20):
        world.step(1 / 20)
        positions.add(tuple(round(c, 2) for c in world.target_position()))
    assert len(positions) > 100  # it walks ...
    assert (4.0, 3.0) in positions  # ... and comes back round


def test_first_person_is_the_target_unless_told():
    cfg = {"people": [{"waypoints": [[1, 1]]}, {"waypoints": [[2, 2]]}]}
    world = World.from_config(cfg, seed=0)
    assert [s.is_target for s in world.people_states()] == [True, False]
    cfg["people"][0]["target"] = False
    cfg["people"][1]["target"] = True
    world = World.from_config(cfg, seed=0)
    assert [s.is_target for s in world.people_states()] == [False, True]
    assert world.target_position() == (2.0, 2.0)
    cfg["people"][1]["target"] = False
    assert World.from_config(cfg, seed=0).target_position() is None


def test_a_persons_jitter_does_not_depend_on_the_others():
    walker = {"name": "a", "waypoints": [[1, 1], [5, 1]], "speed_jitter": 0.3, "pause": 0}
    other = {"name": "b", "waypoints": [[1, 4], [6, 4]], "speed_jitter": 0.3, "pause": 0}

    def track(people):
        world = World.from_config({"people": people}, seed=9)
        out = []
        for _ in range(20 * 20):
            world.step(1 / 20)
            out.append(world.people_states()[0].x)
        return out

    assert track([walker]) == track([walker, other])
