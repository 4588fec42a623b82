"""The pan servo's slew: angle against time for step commands, hand-computed from the SG90's
datasheet speed (60 degrees in 0.1 s: 2.5 degrees per 1/240 s step)."""

import math

import pytest

from fpga_robotics.sim.world.servo import ServoModel, command_to_angle


def test_a_step_command_slews_at_the_datasheet_speed():
    servo = ServoModel()
    servo.command(500)  # +90 degrees
    dt = 1 / 240
    angles = [math.degrees(servo.step(dt)) for _ in range(40)]
    # 600 deg/s: 2.5 deg a step, 90 deg reached after 36 steps (0.15 s), then held.
    assert angles[0] == pytest.approx(2.5)
    assert angles[23] == pytest.approx(60.0)  # 0.1 s: 60 degrees
    assert angles[34] == pytest.approx(87.5)
    assert angles[35:] == pytest.approx([90.0] * 5)
    servo.command(-250)  # to -45 degrees: 135 degrees back, 54 steps
    back = [math.degrees(servo.step(dt)) for _ in range(60)]
    assert back[0] == pytest.approx(87.5)
    assert back[52] == pytest.approx(-42.5)
    assert back[53:] == pytest.approx([-45.0] * 7)


def test_commands_map_to_angles_and_clip_at_the_range():
    assert math.degrees(command_to_angle(500)) == pytest.approx(90.0)
    assert math.degrees(command_to_angle(-100)) == pytest.approx(-18.0)
    assert math.degrees(command_to_angle(511)) == pytest.approx(90.0)  # beyond the end stop
    assert math.degrees(command_to_angle(-512)) == pytest.approx(-90.0)


def test_the_horn_turns_at_full_speed_until_it_is_there():
    # Its rate is the pan camera's turn on top of the body's (the sensor model's motion blur).
    servo = ServoModel()
    assert servo.rate == 0.0
    servo.command(-50)  # -9 degrees: 3.6 steps of 2.5 degrees
    for _ in range(3):
        assert math.degrees(servo.rate) == pytest.approx(-600.0)
        servo.step(1 / 240)
    assert math.degrees(servo.rate) == pytest.approx(-600.0)  # 1.5 degrees still to go
    servo.step(1 / 240)
    assert math.degrees(servo.angle) == pytest.approx(-9.0) and servo.rate == 0.0
