"""DriveMotors: the robot's wheel motors, from DPS commands to wheel speeds and robot twist.

Each wheel's speed follows its target with a limited acceleration (the motor controller's
ramp) and is clamped to the motor's maximum speed. Together these are the robot's "motor
power"; traction (how hard the wheels can push the body) is applied in the physics.
"""

from .kinematics import DEG, dps_to_twist, wheels_to_twist

__all__ = ["DriveMotors", "WheelMotor"]


class WheelMotor:
    """One wheel: speed (rad/s) slews towards the target at ``accel`` (rad/s^2), within
    ``+-max_speed``."""

    __slots__ = ("accel", "max_speed", "speed", "target")

    def __init__(self, max_speed, accel):
        self.max_speed = max_speed
        self.accel = accel
        self.target = 0.0
        self.speed = 0.0

    def set_target(self, rad_s):
        self.target = max(-self.max_speed, min(self.max_speed, rad_s))

    def step(self, dt):
        delta = self.target - self.speed
        limit = self.accel * dt
        if delta > limit:
            self.speed += limit
        elif delta < -limit:
            self.speed -= limit
        else:
            self.speed = self.target
        return self.speed


class DriveMotors:
    """The robot's two wheel motors, commanded in degrees per second like the GoPiGo3.

    Parameters
    ----------
    spec : RobotSpec
        Wheel geometry, ``max_wheel_dps`` and ``wheel_accel_dps2``.
    """

    def __init__(self, spec):
        self.spec = spec
        max_speed = spec.max_wheel_dps * DEG
        accel = spec.wheel_accel_dps2 * DEG
        self.left = WheelMotor(max_speed, accel)
        self.right = WheelMotor(max_speed, accel)
        self.command_dps = (0.0, 0.0)

    def set_wheel_dps(self, left_dps, right_dps):
        """Set the wheel speed targets (degrees per second, positive drives forward)."""
        self.command_dps = (float(left_dps), float(right_dps))
        self.left.set_target(left_dps * DEG)
        self.right.set_target(right_dps * DEG)

    def step(self, dt):
        """Advance the ramps by ``dt`` seconds; returns the wheel speeds (left, right), rad/s."""
        return self.left.step(dt), self.right.step(dt)

    def wheel_speeds(self):
        """Current wheel speeds (left, right), rad/s."""
        return self.left.speed, self.right.speed

    def commanded_twist(self):
        """``(v, w)`` the current DPS command asks for, by the real kinematics (not clamped,
        not ramped: what the design commanded)."""
        return dps_to_twist(*self.command_dps, self.spec.wheel_radius, self.spec.wheel_separation)

    def motor_twist(self):
        """``(v, w)`` of the wheels' current (ramped, clamped) speeds."""
        return wheels_to_twist(
            self.left.speed, self.right.speed, self.spec.wheel_radius, self.spec.wheel_separation
        )
