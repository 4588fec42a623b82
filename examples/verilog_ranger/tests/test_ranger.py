"""The Verilog ranger in closed loop: it comes up to the wall and stops 300 mm from it,
measuring the gap as the world has it."""

from pathlib import Path

import pytest

from fpga_robotics.testing import run

HERE = Path(__file__).parent.parent
#: ranger.toml's wall (x = room width) and the sensor's mount ahead of the robot's centre.
WALL_X, SENSOR_FORWARD = 3.0, 0.1


@pytest.fixture(scope="module")
def approach():
    return run(HERE / "ranger.toml")


def test_the_scenario_passes(approach):
    approach.assert_passes()


def test_it_stops_300_mm_from_the_wall(approach):
    traj = approach.trajectory
    gap_mm = 1000 * (WALL_X - SENSOR_FORWARD - traj["x"])
    # It slows in proportion to the gap left, so it ends just beyond STOP_MM.
    assert 300 <= gap_mm[-1] < 330
    # Its own last measurement (the port map's extra output "range") is that gap.
    assert abs(traj["design.range"][-1] - gap_mm[-1]) < 5
    # Full speed while the wall is far (its measurement over 600 mm), slower near it.
    far = traj["design.range"] > 600
    assert (traj["motor_left"][far] == 300).all()
    near = traj["design.range"] < 400
    assert near.any() and (traj["motor_left"][near] < 100).all()


def test_a_wall_inside_the_sensors_blind_zone_is_hit():
    # The design's blind spot, and a test that can fail: a module that hears nothing nearer
    # than 350 mm answers with its time-out pulse, which the design reads as "far away", so
    # it speeds up again just before the wall.
    result = run(
        HERE / "ranger.toml", overrides=["robot.sensors[0].min_range=0.35", "sim.duration=20"]
    )
    assert result.check("max_wall_collisions").status == "fail"
    assert result.trajectory["design.range"].max() > 6000  # the time-out, read as a range
