"""Differential-drive kinematics: wheel speeds to robot twist and back.

The published system converted DPS to (V, W) with empirically tuned constants that were
about half the true values; here the real kinematics is used: ``v = r*(wl+wr)/2`` and
``w = r*(wr-wl)/L`` with wheel speeds in rad/s, wheel radius ``r`` and wheel separation ``L``
in metres.
"""

import math

__all__ = [
    "DEG",
    "dps_to_rad",
    "dps_to_twist",
    "rad_to_dps",
    "twist_to_wheels",
    "wheels_to_twist",
]

#: Radians per degree.
DEG = math.pi / 180.0


def dps_to_rad(dps):
    """Degrees per second to radians per second."""
    return dps * DEG


def rad_to_dps(rad_s):
    """Radians per second to degrees per second."""
    return rad_s / DEG


def wheels_to_twist(left_rad_s, right_rad_s, wheel_radius, wheel_separation):
    """Robot twist ``(v, w)`` (m/s, rad/s counter-clockwise) from wheel speeds in rad/s."""
    v = wheel_radius * (left_rad_s + right_rad_s) / 2.0
    w = wheel_radius * (right_rad_s - left_rad_s) / wheel_separation
    return v, w


def dps_to_twist(left_dps, right_dps, wheel_radius, wheel_separation):
    """Robot twist ``(v, w)`` from wheel speeds in degrees per second (the design's unit)."""
    return wheels_to_twist(left_dps * DEG, right_dps * DEG, wheel_radius, wheel_separation)


def twist_to_wheels(v, w, wheel_radius, wheel_separation):
    """Wheel speeds ``(left, right)`` in rad/s that produce the twist ``(v, w)``."""
    half = w * wheel_separation / 2.0
    return (v - half) / wheel_radius, (v + half) / wheel_radius
