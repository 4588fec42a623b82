"""The avoider in closed loop: it drives about the room for 30 s and touches nothing."""

from pathlib import Path

import pytest

from fpga_robotics.testing import run

SCENARIOS = Path(__file__).parent.parent / "scenarios"


@pytest.fixture(scope="module")
def room():
    return run(SCENARIOS / "room.toml", seed=0)


def test_the_room_scenario_passes(room):
    room.assert_passes()
    assert room.check("max_wall_collisions").value == 0
    # It kept moving: more than 3 m in 30 s (at most 5.1 m at 300 DPS straight on).
    assert room.summary["path_length_m"] > 3.0


def test_it_turns_exactly_while_something_is_near(room):
    traj = room.trajectory
    turning = traj["design.turning"] == 1
    assert turning.any() and (~turning).any()
    # The wheels follow the design's rule: on the spot while turning, straight on otherwise.
    assert (traj["motor_left"][turning] == -150).all()
    assert (traj["motor_right"][turning] == 150).all()
    assert (traj["motor_left"][~turning] == 300).all()
    # It turned on its own measurements: nearer than turn_mm (400 mm).
    assert (traj["design.distance_mm"][turning] < 400).all()


def test_the_furniture_scenario_passes():
    run(SCENARIOS / "furniture.toml", seed=1).assert_passes()


def test_turning_too_late_hits_the_wall():
    # The test can fail: at 100 mm the robot cannot turn before its body meets the wall.
    result = run(SCENARIOS / "room.toml", params={"turn_mm": 100}, seed=0)
    assert result.check("max_wall_collisions").status == "fail"
