"""A person's body for the 3D renderer: its parts, their sizes and colours, and the gait.

The body is sized so that seen from the front it covers what the raster renderer's cylinder
covers: the shirt (torso and sleeves) spans the cylinder's diameter ``2 * radius`` from the
hips (0.85 m) to the shoulders (1.45 m) of a 1.75 m person, the trousers the legs below, the
skin the head above (``sim.world.people.person_bands``). Heights scale with the person's
height, widths with their radius; the colours come from the cylinder's bands.

The gait is a function of two numbers the world keeps per person: the distance walked, which
sets the phase (one cycle, two steps, every ``CYCLE_LENGTH`` m at the reference height), and
the speed, which sets how far the limbs swing (still when standing, full swing from
``FULL_SWING_SPEED``). The limbs therefore swing at ``speed / cycle_length`` cycles a second.
"""

import math
from dataclasses import dataclass

__all__ = [
    "CYCLE_LENGTH",
    "FULL_SWING_SPEED",
    "REFERENCE_HEIGHT",
    "REFERENCE_RADIUS",
    "SWING",
    "BodyColors",
    "body_colors",
    "cycle_length",
    "gait_angles",
]

REFERENCE_HEIGHT = 1.75
REFERENCE_RADIUS = 0.2
#: Distance walked per gait cycle (two steps) by a person of the reference height, m.
CYCLE_LENGTH = 1.0
#: From this speed (m/s) on the limbs swing through their full amplitude.
FULL_SWING_SPEED = 0.5
#: Full swing amplitudes, rad: hip (leg forward/back), knee bend, shoulder, elbow bend.
SWING = {"hip": 0.42, "knee": 0.6, "shoulder": 0.35, "elbow": 0.3}
#: Joint names in the order the renderer declares them (left then right).
JOINTS = ("hip_l", "knee_l", "hip_r", "knee_r", "shoulder_l", "elbow_l", "shoulder_r", "elbow_r")

SHOES = (0.12, 0.1, 0.09)
HAIR = (0.2, 0.13, 0.08)


@dataclass(frozen=True)
class BodyColors:
    shirt: tuple
    trousers: tuple
    skin: tuple
    shoes: tuple = SHOES
    hair: tuple = HAIR


def body_colors(bands, height):
    """Shirt, trousers and skin colours from a cylinder's bands: the band covering the chest
    (1.2 m at the reference height), the knees (0.45 m) and the face (1.62 m); a height no
    band covers keeps a neutral default."""
    s = height / REFERENCE_HEIGHT

    def at(z, default):
        for band in bands:
            if band.z0 <= z * s <= band.z1:
                return tuple(band.color)
        return default

    return BodyColors(
        shirt=at(1.2, (0.5, 0.5, 0.5)),
        trousers=at(0.45, (0.2, 0.2, 0.25)),
        skin=at(1.62, (0.87, 0.68, 0.56)),
    )


def person_height(bands):
    """The top of the highest band (the cylinder's height), m."""
    return max((b.z1 for b in bands), default=REFERENCE_HEIGHT)


def cycle_length(height):
    """Distance walked per gait cycle (m) by a person ``height`` m tall."""
    return CYCLE_LENGTH * height / REFERENCE_HEIGHT


def gait_angles(walked, speed, height):
    """Joint angles (rad) of ``JOINTS`` for a person who has walked ``walked`` m and moves at
    ``speed`` m/s. Hip and shoulder angles are forward swings (positive: the limb ahead of
    the body); knee and elbow angles are bends (>= 0)."""
    phase = 2.0 * math.pi * walked / cycle_length(height)
    a = min(1.0, max(0.0, speed) / FULL_SWING_SPEED)
    s = math.sin(phase)
    # The knee bends while its leg swings forward (the second half of its backward swing).
    bend_l = max(0.0, math.sin(phase + math.pi / 2))
    bend_r = max(0.0, math.sin(phase - math.pi / 2))
    return {
        "hip_l": a * SWING["hip"] * s,
        "hip_r": -a * SWING["hip"] * s,
        "knee_l": a * SWING["knee"] * bend_l,
        "knee_r": a * SWING["knee"] * bend_r,
        # Arms swing against the legs on the same side.
        "shoulder_l": -a * SWING["shoulder"] * s,
        "shoulder_r": a * SWING["shoulder"] * s,
        "elbow_l": 0.1 + a * SWING["elbow"] * max(0.0, -s),
        "elbow_r": 0.1 + a * SWING["elbow"] * max(0.0, s),
    }
