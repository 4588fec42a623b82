"""Differential-drive kinematics and the motor model, against hand-computed values."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from fpga_robotics.sim.world import GOPIGO3, TURTLEBOT2, dps_to_twist, twist_to_wheels
from fpga_robotics.sim.world.kinematics import wheels_to_twist
from fpga_robotics.sim.world.motors import DriveMotors, WheelMotor


def test_robot_geometry_is_the_real_one():
    assert TURTLEBOT2.wheel_radius == pytest.approx(0.070 / 2)
    assert TURTLEBOT2.wheel_separation == pytest.approx(0.230)
    assert GOPIGO3.wheel_radius == pytest.approx(0.0665 / 2)
    assert GOPIGO3.wheel_separation == pytest.approx(0.117)


def test_both_wheels_one_turn_per_second_drives_one_circumference():
    v, w = dps_to_twist(360, 360, 0.035, 0.230)
    assert v == pytest.approx(0.035 * 2 * math.pi)  # 0.2199 m/s
    assert v == pytest.approx(0.2199, abs=1e-4)
    assert w == 0.0


def test_opposite_wheels_turn_in_place():
    v, w = dps_to_twist(-90, 90, 0.035, 0.230)
    assert v == pytest.approx(0.0, abs=1e-15)
    # wl = -pi/2, wr = +pi/2 rad/s: w = r * pi / L, counter-clockwise (right wheel forward).
    assert w == pytest.approx(0.035 * math.pi / 0.230)


def test_gopigo3_one_wheel_forward_turns_right():
    v, w = dps_to_twist(180, 0, GOPIGO3.wheel_radius, GOPIGO3.wheel_separation)
    assert v == pytest.approx(0.03325 * math.pi / 2)
    assert w == pytest.approx(-0.03325 * math.pi / 0.117)


def test_not_the_published_empirical_constants():
    # The published harness used v = 2 (R + L) / 3192 and w = (R - L) * 0.0015, tuned by
    # hand; the real kinematics for the TurtleBot2 differs from them by a lot.
    v, w = dps_to_twist(300, 500, 0.035, 0.230)
    assert v == pytest.approx(0.035 * 400 * math.pi / 180)
    assert abs(v / (2 * (300 + 500) / 3192) - 1) > 0.3
    assert abs(w / ((500 - 300) * 0.0015) - 1) > 0.3


@given(st.floats(-2, 2), st.floats(-6, 6))
def test_twist_to_wheels_inverts_wheels_to_twist(v, w):
    left, right = twist_to_wheels(v, w, 0.035, 0.23)
    v2, w2 = wheels_to_twist(left, right, 0.035, 0.23)
    assert v2 == pytest.approx(v, abs=1e-9)
    assert w2 == pytest.approx(w, abs=1e-9)


def test_wheel_motor_ramps_at_its_acceleration_and_clamps():
    motor = WheelMotor(max_speed=10.0, accel=20.0)
    motor.set_target(15.0)  # above the maximum: clamped to 10
    assert motor.target == 10.0
    speeds = [motor.step(0.01) for _ in range(60)]
    assert speeds[0] == pytest.approx(0.2)
    assert speeds[24] == pytest.approx(5.0)  # 25 steps of 0.2 rad/s
    assert speeds[49] == pytest.approx(10.0)  # reached after 10 / 20 = 0.5 s
    assert speeds[-1] == 10.0
    motor.set_target(-10.0)
    down = [motor.step(0.01) for _ in range(100)]
    assert down[49] == pytest.approx(0.0, abs=1e-9)
    assert down[-1] == pytest.approx(-10.0)


def test_drive_motors_commanded_twist_is_the_raw_command():
    motors = DriveMotors(TURTLEBOT2)
    motors.set_wheel_dps(360, 360)
    assert motors.commanded_twist() == pytest.approx((0.035 * 2 * math.pi, 0.0))
    assert motors.motor_twist() == (0.0, 0.0)  # nothing ramped yet
    motors.set_wheel_dps(5000, 5000)  # beyond the motors: commanded as asked, run clamped
    for _ in range(1000):
        motors.step(0.005)
    assert motors.commanded_twist()[0] == pytest.approx(0.035 * 5000 * math.pi / 180)
    assert motors.motor_twist()[0] == pytest.approx(TURTLEBOT2.max_speed)
