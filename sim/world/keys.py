"""The keys of the world's sections (``room``, ``robot``, ``people``, ``lighting``), each
declared once: type, default, valid range, unit and meaning (docs/scenarios.md lists them).

A default of ``None`` means the default depends on other keys (a divider is taller than a
box, the robot model gives its own mass); ``sim.world.config`` fills it in and checks the
relations between keys (inside the room, names used once).
"""

from typing import Annotated

from pydantic import BeforeValidator, Field

from .robots import ROBOT_MODELS
from .schema import (
    Flag,
    KeyModel,
    Number,
    Tables,
    Text,
    Vector,
    check_of,
    checked,
    fail,
    show,
)

__all__ = [
    "DEFAULT_SHIRT",
    "DEFAULT_SKIN",
    "DEFAULT_TROUSERS",
    "MAX_TIME",
    "WORLD_KEY_MODELS",
    "FurnitureKeys",
    "LightingKeys",
    "LineKeys",
    "PersonKeys",
    "RobotKeys",
    "RoomKeys",
    "TerrainKeys",
]

#: The latest time (s) a world description may name (keyframes, start delays): one day.
MAX_TIME = 86400.0

DEFAULT_SHIRT = (0.85, 0.1, 0.1)
DEFAULT_TROUSERS = (0.15, 0.15, 0.22)
DEFAULT_SKIN = (0.87, 0.68, 0.56)

Color = Vector(3, "a colour [r, g, b] with each in 0..1", ge=0, le=1)
Point = Vector(2, "a point [x, y] in m")
Size = Vector(2, "[length, width] in m", ge=0.01, le=100)
Angle = Number(ge=-360, le=360, unit="deg")


def _points(least, what):
    """An array of at least ``least`` points [x, y] (``what``: the message's description)."""
    point = check_of(Point)

    def check(value):
        if not isinstance(value, list) or len(value) < least:
            fail(f"must be {what}, got {show(value)}")
        return tuple(checked(point, p, f"[{i}]") for i, p in enumerate(value))

    return BeforeValidator(check)


def _pause(value):
    """One pause (s) or one per waypoint (their count is checked in config)."""
    check = check_of(Number(ge=0, le=3600, unit="s"))
    if isinstance(value, list):
        return tuple(checked(check, v, f"[{i}]") for i, v in enumerate(value))
    return check(value)


def _keyframes(value):
    """``[[t, ambient, intensity], ...]``, t non-decreasing."""
    if not isinstance(value, list):
        fail(f"must be an array of [t, ambient, intensity], got {show(value)}")
    t = check_of(Number(ge=0, le=MAX_TIME, unit="s"))
    level = check_of(Number(ge=0, le=2))
    frames = []
    for i, k in enumerate(value):
        if not isinstance(k, (list, tuple)) or len(k) != 3:
            fail(f"must be [t, ambient, intensity], got {show(k)}", sub=f"[{i}]")
        frame = (
            checked(t, k[0], f"[{i}][0] (t)"),
            checked(level, k[1], f"[{i}][1] (ambient)"),
            checked(level, k[2], f"[{i}][2] (intensity)"),
        )
        if frames and frame[0] < frames[-1][0]:
            fail(
                f"must not be earlier than the previous keyframe's ({frames[-1][0]:g} s), "
                f"got {frame[0]:g}",
                sub=f"[{i}][0] (t)",
            )
        frames.append(frame)
    return tuple(frames)


def _tables(model, key):
    return Annotated[list[model], *Tables(f"an array of tables ([[{key}]])")]


class FurnitureKeys(KeyModel):
    name: Text(doc="its name (default furnitureN)") = None
    type: Text(choices=("box", "divider"), doc="box or divider") = "box"
    center: Annotated[Point, Field(description="the centre [x, y] in m")]
    size: Size = None  # (1, 0.6) for a box, (1.5, 0.03) for a divider
    angle_deg: Angle = 0.0
    height: Number(gt=0, le=10, unit="m", doc="0.75 for a box, 1.6 for a divider") = None
    color: Color = None  # wood for a divider, grey for a box
    present_until: Number(gt=0, le=MAX_TIME, unit="s", doc="leaves the room then") = None


class LineKeys(KeyModel):
    name: Text(doc="its name (default lineN)") = None
    # At least 2 points (3 when closed): config checks the count, with the line's kind.
    points: Annotated[object, Field(description="the centreline [[x, y], ...] in m")] = None
    closed: Flag(doc="a loop") = False
    width: Number(gt=0, le=1, unit="m", doc="tape width") = 0.019
    color: Color = (0.0, 0.0, 0.0)


class TerrainKeys(KeyModel):
    """A polygon (``points``) or a rectangle (``center`` with ``size`` and ``angle_deg``)."""

    name: Text(doc="its name (default terrainN)") = None
    points: Annotated[object, _points(3, "an array of at least 3 points [x, y]")] = None
    center: Point = None
    size: Size = (1.0, 1.0)
    angle_deg: Angle = 0.0
    friction: Number(ge=0.01, le=10, doc="traction factor") = 1.0
    slope_deg: Number(ge=0, le=45, unit="deg") = 0.0
    slope_dir_deg: Angle = 0.0
    color: Color = None  # None: not drawn (a wet floor looks like the floor)


class RoomKeys(KeyModel):
    width: Number(gt=0.5, le=100, unit="m", doc="x extent") = 8.0
    depth: Number(gt=0.5, le=100, unit="m", doc="y extent") = 6.0
    height: Number(gt=0.2, le=20, unit="m", doc="wall and ceiling height") = 2.5
    wall_color: Color = (0.8, 0.78, 0.72)
    floor_color: Color = (0.55, 0.55, 0.5)
    ceiling_color: Color = (0.9, 0.9, 0.9)
    furniture: _tables(FurnitureKeys, "room.furniture") = ()
    terrain: _tables(TerrainKeys, "room.terrain") = ()
    lines: _tables(LineKeys, "room.lines") = ()


class RobotKeys(KeyModel):
    """``None``: the robot model's value."""

    model: Text(choices=tuple(ROBOT_MODELS)) = "turtlebot2"
    start: Point = None  # (min(1.5, room.width / 2 - 0.5), room.depth / 2)
    heading_deg: Angle = 0.0
    mass: Number(ge=0.05, le=1000, unit="kg") = None
    body_radius: Number(ge=0.02, le=2, unit="m") = None
    wheel_radius: Number(ge=0.005, le=1, unit="m") = None
    wheel_separation: Number(ge=0.02, le=3, unit="m") = None
    max_wheel_dps: Number(gt=0, le=100000, unit="deg/s") = None
    wheel_accel_dps2: Number(gt=0, le=1e6, unit="deg/s^2") = None
    traction_force: Number(gt=0, le=1e5, unit="N") = None
    camera_height: Number(gt=0, le=5, unit="m") = None
    camera_forward: Number(ge=-2, le=2, unit="m") = None
    traction_torque: Number(gt=0, le=1e5, unit="N m", doc="force * separation / 2") = None
    camera_tilt_deg: Number(ge=-85, le=85, unit="deg") = None
    com_height: Number(gt=0, le=5, unit="m") = None
    support_half_length: Number(gt=0, le=5, unit="m") = None
    support_half_width: Number(gt=0, le=5, unit="m") = None
    motor_step_response: Number(gt=0, le=10, unit="s") = None
    motor_gain_error: Number(ge=0, le=0.9) = 0.0
    motor_noise_dps: Number(ge=0, le=10000, unit="deg/s") = 0.0
    slip_rate_hz: Number(ge=0, le=100, unit="1/s") = 0.0
    slip_duration_s: Number(gt=0, le=60, unit="s") = 0.2
    slip_traction: Number(ge=0.01, le=1) = 0.2


class PersonKeys(KeyModel):
    name: Text(doc="its name (default personN)") = None
    target: Flag(doc="the person the robot follows (default: the first)") = None
    waypoints: Annotated[
        object,
        _points(1, "a non-empty array of [x, y] points"),
        Field(description="an array of [x, y] points in m"),
    ]
    speed: Number(gt=0, le=5, unit="m/s") = 0.5
    speed_jitter: Number(ge=0, le=0.9) = 0.0
    pause: Annotated[
        object, BeforeValidator(_pause), Field(description="s, one or per waypoint")
    ] = 1.0
    loop: Flag() = True
    start_delay: Number(ge=0, le=MAX_TIME, unit="s") = 0.0
    yield_gap: Number(ge=0, le=5, unit="m") = 0.0
    radius: Number(ge=0.05, le=1, unit="m") = 0.2
    height: Number(ge=0.5, le=2.5, unit="m") = 1.75
    shirt_color: Color = DEFAULT_SHIRT
    trousers_color: Color = DEFAULT_TROUSERS
    skin_color: Color = DEFAULT_SKIN


class LightingKeys(KeyModel):
    ambient: Number(ge=0, le=2) = 0.6
    intensity: Number(ge=0, le=2) = 0.5
    direction: Vector(3, "a vector [dx, dy, dz], each -1000..1000", ge=-1000, le=1000) = (
        1.0,
        0.5,
        -1.0,
    )
    keyframes: Annotated[object, BeforeValidator(_keyframes)] = ()
    interpolation: Text(choices=("linear", "step")) = "linear"


#: Every world table's model by its key path (arrays of tables by the array's path).
WORLD_KEY_MODELS = {
    "room": RoomKeys,
    "room.furniture": FurnitureKeys,
    "room.terrain": TerrainKeys,
    "room.lines": LineKeys,
    "robot": RobotKeys,
    "people": PersonKeys,
    "lighting": LightingKeys,
}
