"""Robot models: the real geometry of the robots the published work used, plus motor power.

Every field can be overridden from the scenario's ``[robot]`` section; the presets are the
starting point. Traction (``traction_force``, ``traction_torque``) is a property of the
motors and the floor, not of the mass: a heavier robot with the same motors accelerates more
slowly, as it should.
"""

from dataclasses import dataclass, replace

from .kinematics import DEG

__all__ = ["GOPIGO3", "ROBOT_MODELS", "TURTLEBOT2", "RobotSpec", "robot_model"]


@dataclass(frozen=True)
class RobotSpec:
    """Geometry, mass and motor power of a differential-drive robot.

    Parameters
    ----------
    name : str
        Model name (``"turtlebot2"``, ``"gopigo3"``).
    wheel_radius : float
        m.
    wheel_separation : float
        Distance between the wheels' contact points, m.
    body_radius : float
        Radius of the round footprint used for collisions, m.
    mass : float
        kg.
    max_wheel_dps : float
        Maximum wheel speed, degrees per second; faster commands are clamped.
    wheel_accel_dps2 : float
        Maximum change of a wheel's speed, degrees per second squared (the motor
        controller's ramp).
    traction_force : float
        Largest total force the wheels can push the body with, N (the smaller of motor
        force and grip). Limits linear acceleration to ``traction_force / mass``.
    traction_torque : float
        Largest torque about the vertical axis, N m (for turning).
    camera_height : float
        Height of the camera above the floor, m.
    camera_forward : float
        Camera position ahead of the robot's centre, m.
    camera_tilt : float
        Camera pitch, rad, positive looks up.
    """

    name: str
    wheel_radius: float
    wheel_separation: float
    body_radius: float
    mass: float
    max_wheel_dps: float
    wheel_accel_dps2: float
    traction_force: float
    traction_torque: float
    camera_height: float
    camera_forward: float
    camera_tilt: float = 0.0

    @property
    def max_speed(self):
        """Top linear speed with both wheels at ``max_wheel_dps``, m/s."""
        return self.wheel_radius * self.max_wheel_dps * DEG

    @property
    def motor_accel(self):
        """Linear acceleration the motor ramp allows, m/s^2."""
        return self.wheel_radius * self.wheel_accel_dps2 * DEG

    @property
    def moment(self):
        """Moment of inertia of the body as a uniform disc, kg m^2."""
        return 0.5 * self.mass * self.body_radius ** 2

    def with_overrides(self, **fields):
        """A copy with some fields replaced."""
        return replace(self, **fields)


def _turning_torque(force, separation):
    # Each wheel pushes with half the force, in opposite directions, at half the separation.
    return force * separation / 2.0


# TurtleBot2 (Kobuki base): wheel diameter 70 mm, separation 230 mm, footprint 354 mm,
# about 6.3 kg with its mast and sensor, top speed 0.7 m/s. Ramp 1 m/s^2; the traction is
# twice what that ramp needs at the nominal mass.
_TB2_ACCEL_DPS2 = 1.0 / 0.035 / DEG
TURTLEBOT2 = RobotSpec(
    name="turtlebot2",
    wheel_radius=0.035,
    wheel_separation=0.230,
    body_radius=0.177,
    mass=6.3,
    max_wheel_dps=float(round(0.7 / 0.035 / DEG)),
    wheel_accel_dps2=float(round(_TB2_ACCEL_DPS2)),
    traction_force=12.6,
    traction_torque=_turning_torque(12.6, 0.230),
    camera_height=0.30,
    camera_forward=0.10,
)

# GoPiGo3: wheel diameter 66.5 mm, wheel base 117 mm, about 0.8 kg with batteries. The
# design limits the motors to 512 DPS (SET_MOTOR_LIMITS); ramp 1500 DPS/s (0.87 m/s^2).
_GPG3_ACCEL = 0.03325 * 1500 * DEG
GOPIGO3 = RobotSpec(
    name="gopigo3",
    wheel_radius=0.0665 / 2,
    wheel_separation=0.117,
    body_radius=0.11,
    mass=0.8,
    max_wheel_dps=512.0,
    wheel_accel_dps2=1500.0,
    traction_force=round(2 * 0.8 * _GPG3_ACCEL, 2),
    traction_torque=round(_turning_torque(2 * 0.8 * _GPG3_ACCEL, 0.117), 4),
    camera_height=0.12,
    camera_forward=0.08,
)

ROBOT_MODELS = {spec.name: spec for spec in (TURTLEBOT2, GOPIGO3)}


def robot_model(name):
    """The preset called ``name``; ``KeyError`` if there is none."""
    return ROBOT_MODELS[name]

