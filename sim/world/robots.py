"""Robot models: the real geometry of the robots the published work used, plus motor power.

Every field can be overridden from the scenario's ``[robot]`` section; the presets are the
starting point. Traction (``traction_force``, ``traction_torque``) is a property of the
motors and the floor, not of the mass: a heavier robot with the same motors accelerates more
slowly, as it should.
"""

from dataclasses import dataclass, replace

from .kinematics import DEG

#: Standard gravity, m/s^2.
G = 9.80665

__all__ = ["GOPIGO3", "ROBOT_MODELS", "TURTLEBOT2", "G", "RobotSpec", "robot_model"]


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
    com_height : float
        Height of the centre of mass above the floor, m (tip-over model).
    support_half_length : float
        Horizontal distance from the centre of mass to the nearest edge of the support
        polygon along the direction of travel (the wheel axle or a caster's contact), m.
    support_half_width : float
        Horizontal distance from the centre of mass to the edge of the support polygon
        straight across the direction of travel, m (sideways tipping on a slope).
    motor_step_response : float or None
        None (the presets): the motor controller ramps every command at ``wheel_accel_dps2``,
        so a jump of the command never tips the robot. A number: the motors follow a jump of
        the command within this time, s (a controller without a ramp): a jump of D DPS asks
        the body for ``wheel_radius * D * DEG / motor_step_response`` m/s^2.

    The robot tips over (quasi-statically) when its longitudinal acceleration exceeds
    ``tip_accel = g * support_half_length / com_height``: the inertial force at the centre of
    mass then has a larger moment about the support edge than the weight. The body gets at
    most ``traction_force / mass`` (times the floor's factor), so a robot whose traction is
    below ``tip_accel * mass`` never tips on level floor. On a ramp pitching it by ``p``
    along its heading it tips when ``|a + g sin(p)| > tip_accel * cos(p)``; rolled by ``q``
    across it, when the sideways load, ``g sin(q)`` but no more than the traction holds, exceeds
    ``tip_accel_sideways * cos(q)``, ``tip_accel_sideways = g * support_half_width /
    com_height``.
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
    com_height: float = 0.2
    support_half_length: float = 0.1
    motor_step_response: float | None = None
    support_half_width: float = 0.1

    @property
    def tip_accel(self):
        """Longitudinal acceleration that tips the robot over, m/s^2 (quasi-static)."""
        return G * self.support_half_length / self.com_height

    @property
    def tip_accel_sideways(self):
        """Sideways acceleration (or gravity's sideways part on a slope) that tips the robot
        over onto its side, m/s^2 (quasi-static)."""
        return G * self.support_half_width / self.com_height

    @property
    def tip_step_dps(self):
        """The largest jump of a wheel's command (DPS) the robot survives: the jump whose
        step response asks for ``tip_accel``; None without ``motor_step_response``."""
        if self.motor_step_response is None:
            return None
        return self.tip_accel * self.motor_step_response / (self.wheel_radius * DEG)

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
        return 0.5 * self.mass * self.body_radius**2

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
    # Tip-over: the Kobuki base (Kobuki user guide: 351.5 mm diameter, 124 mm high, 2.35 kg)
    # rests on its two wheels on the centre line and two casters, 0.115 m ahead and 0.135 m
    # behind the axle (yujinrobot/kobuki, kobuki_description/urdf/kobuki.urdf.xacro: the
    # caster joints); the nearer, front one is the edge. The TurtleBot2's plates and sensor
    # (to 420 mm) raise the centre of mass to an estimated 0.20 m (no published figure; the
    # URDF's masses are placeholders). tip_accel = 9.81 * 0.115 / 0.20 = 5.6 m/s^2.
    com_height=0.20,
    support_half_length=0.115,
    # Sideways the centre of mass, on the axle between the wheels (the casters are on the
    # centre line), leaves the support over a wheel's contact, half the wheel separation away:
    # a robot parked across a slope falls on its side beyond atan(0.115 / 0.20) = 29.9 deg.
    support_half_width=0.115,
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
    # Tip-over: the GoPiGo3 rests on its two wheels at the front and one ball caster at the
    # back. Its ROS description (gpg_description/urdf/gpg.urdf.xacro of the book "Hands-On ROS
    # for Robotics Programming", B. Japon, 2020: base_link "at the center of gravity of GoPiGo3
    # body") puts the centre of mass 0.075 m above the floor and 0.06 m behind the wheel axle,
    # the caster 0.132 m behind it: the axle, 0.06 m away, is the nearer edge, so braking (or
    # reversing hard) pitches it forward at tip_accel = 9.81 * 0.06 / 0.075 = 7.8 m/s^2. The
    # same edge is used in both directions (the model is symmetric). A scenario may set
    # robot.motor_step_response (docs/stories.md, story c).
    com_height=0.075,
    support_half_length=0.06,
    # Sideways the support is the triangle of the wheels (0.0585 m either side of the axle's
    # middle) and the caster 0.132 m behind it: straight across from the centre of mass, 0.06 m
    # behind the axle, its edge lies 0.0585 * (1 - 0.06 / 0.132) = 0.032 m away, so parked
    # across a slope it falls on its side beyond atan(0.032 / 0.075) = 23.1 deg.
    support_half_width=0.032,
)

ROBOT_MODELS = {spec.name: spec for spec in (TURTLEBOT2, GOPIGO3)}


def robot_model(name):
    """The preset called ``name``; ``KeyError`` if there is none."""
    return ROBOT_MODELS[name]
