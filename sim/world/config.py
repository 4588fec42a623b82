"""The world part of a scenario: schema, defaults and validation.

``parse_world_config(cfg)`` turns the ``room``, ``robot``, ``people`` and ``lighting``
sections of a scenario (plain dicts, as read from TOML) into frozen dataclasses, filling in
defaults. Anything wrong (a wrong type, a value out of range, an unknown key: usually a typo)
raises ``WorldConfigError`` whose message names the key path, the expected type or range and
the value found. docs/scenarios.md documents every key.
"""

import difflib
import math
from dataclasses import dataclass

import numpy as np
from pydantic_core import PydanticCustomError

from fpga_robotics.hw.errors import UserError

from .keys import (
    DEFAULT_SHIRT,
    DEFAULT_SKIN,
    DEFAULT_TROUSERS,
    MAX_TIME,
    FurnitureKeys,
    LightingKeys,
    LineKeys,
    PersonKeys,
    Point,
    RobotKeys,
    RoomKeys,
    TerrainKeys,
)
from .kinematics import DEG
from .markings import FloorLine
from .robots import ROBOT_MODELS
from .schema import check_of, show, validate
from .terrain import TerrainPatch

__all__ = [
    "DEFAULT_SHIRT",
    "DEFAULT_SKIN",
    "DEFAULT_TROUSERS",
    "DIVIDER_WOOD",
    "MAX_TIME",
    "WORLD_SECTIONS",
    "FurnitureConfig",
    "LightingConfig",
    "PersonConfig",
    "RobotConfig",
    "RoomConfig",
    "WorldConfig",
    "WorldConfigError",
    "parse_world_config",
    "start_name",
]

#: The scenario sections that describe the world.
WORLD_SECTIONS = ("room", "robot", "people", "lighting")

#: Red-brown wood: the divider that the published colour filter mistook for a red shirt.
DIVIDER_WOOD = (0.55, 0.27, 0.15)
_BOX_COLOR = (0.45, 0.42, 0.38)


class WorldConfigError(UserError, ValueError):
    """A scenario's world description is invalid; the message names the key path."""


@dataclass(frozen=True)
class FurnitureConfig:
    name: str
    kind: str  # "box" or "divider"
    center: tuple  # (x, y), m
    size: tuple  # (length along its heading, width across), m
    angle: float  # rad, counter-clockwise from +x
    height: float  # m
    color: tuple  # albedo
    #: World time (s) at which the item leaves the room (physics, camera, map); None: never.
    present_until: float | None = None

    def corners(self):
        """The footprint's four corners, counter-clockwise."""
        cx, cy = self.center
        hl, hw = self.size[0] / 2.0, self.size[1] / 2.0
        c, s = math.cos(self.angle), math.sin(self.angle)
        local = ((-hl, -hw), (hl, -hw), (hl, hw), (-hl, hw))
        return [(cx + c * x - s * y, cy + s * x + c * y) for x, y in local]


@dataclass(frozen=True)
class RoomConfig:
    width: float  # x extent, m (the room spans 0..width)
    depth: float  # y extent, m (0..depth)
    height: float  # wall height and ceiling height, m
    wall_color: tuple
    floor_color: tuple
    ceiling_color: tuple
    furniture: tuple  # of FurnitureConfig
    terrain: tuple = ()  # of terrain.TerrainPatch, in file order (the last listed wins)
    lines: tuple = ()  # of markings.FloorLine, in file order (drawn over the terrain)


@dataclass(frozen=True)
class Uncertainty:
    """Seeded imperfections of the robot (all zero: the ideal robot, today's runs)."""

    motor_gain_error: float = 0.0  # each wheel's gain is 1 + U(-e, e), drawn once per run
    motor_noise_dps: float = 0.0  # white noise on each wheel's speed, std, deg/s (per 10 ms)
    slip_rate_hz: float = 0.0  # wheel slip events per second (Poisson)
    slip_duration_s: float = 0.2  # each slip's length
    slip_traction: float = 0.2  # traction factor during a slip

    def __bool__(self):
        return bool(self.motor_gain_error or self.motor_noise_dps or self.slip_rate_hz)


@dataclass(frozen=True)
class RobotConfig:
    spec: object  # RobotSpec
    start: tuple  # (x, y), m
    heading: float  # rad
    uncertainty: Uncertainty = Uncertainty()
    default_start: bool = False  # the scenario sets no robot.start: errors must say so


@dataclass(frozen=True)
class PersonConfig:
    name: str
    target: bool
    waypoints: tuple  # ((x, y), ...)
    speed: float  # m/s
    speed_jitter: float  # fraction: each leg's speed is speed * (1 + U(-j, j))
    pauses: tuple  # s, one per waypoint
    loop: bool
    start_delay: float  # s
    yield_gap: float  # m: waits rather than walk closer than this to the robot (0: never)
    radius: float
    height: float
    shirt_color: tuple
    trousers_color: tuple
    skin_color: tuple


@dataclass(frozen=True)
class LightingConfig:
    ambient: float
    intensity: float
    direction: tuple
    keyframes: tuple  # ((t, ambient, intensity), ...), t non-decreasing
    interpolation: str  # "linear" or "step"


@dataclass(frozen=True)
class WorldConfig:
    room: RoomConfig
    robot: RobotConfig
    people: tuple  # of PersonConfig
    lighting: LightingConfig


def _fmt(point):
    return "[" + ", ".join(f"{c:g}" for c in point) + "]"


def _keys(model, table, path):
    """The table's keys validated by its model (``sim.world.keys``)."""
    return validate(model, table, path, WorldConfigError)


def _parse_furniture(item, path, index):
    k = _keys(FurnitureKeys, item, path)
    divider = k.type == "divider"
    return FurnitureConfig(
        k.name or f"furniture{index}",
        k.type,
        k.center,
        k.size or ((1.5, 0.03) if divider else (1.0, 0.6)),
        k.angle_deg * DEG,
        k.height or (1.6 if divider else 0.75),
        k.color or (DIVIDER_WOOD if divider else _BOX_COLOR),
        k.present_until,
    )


def _parse_line(item, path, index, room):
    k = _keys(LineKeys, item, path)
    least = 3 if k.closed else 2
    points = k.points
    if not isinstance(points, list) or len(points) < least:
        raise WorldConfigError(
            f"{path}.points must be an array of at least {least} points [x, y] "
            f"({'a closed' if k.closed else 'an open'} line), got "
            f"{show(points) if points is not None else 'nothing'}"
        )
    centreline = tuple(_point(p, f"{path}.points[{i}]") for i, p in enumerate(points))
    w, d = room
    for i, (x, y) in enumerate(centreline):
        if not (0 <= x <= w and 0 <= y <= d):
            raise WorldConfigError(
                f"{path}.points[{i}] {_fmt((x, y))} is outside the room (0..{w:g} x 0..{d:g} m)"
            )
    line = FloorLine(k.name or f"line{index}", centreline, k.width, k.color, k.closed)
    if line.length < 1e-6:
        raise WorldConfigError(f"{path}.points has no length (all the points are the same)")
    return line


def _point(value, path):
    try:
        return check_of(Point)(value)
    except PydanticCustomError as exc:
        raise WorldConfigError(f"{path}{exc.context.get('sub', '')} {exc.message()}") from None


def _crossing_edges(polygon):
    """``(i, j)``: the first two edges of the closed ``polygon`` (edge i from point i to the
    next) that cross each other, or None for a simple polygon. Each edge is tested against
    all the later ones at once (a polygon of thousands of corners in well under a second)."""
    n = len(polygon)
    a = np.asarray(polygon, dtype=float)
    b = np.roll(a, -1, axis=0)  # edge i runs from a[i] to b[i]

    def side(p, q, r):  # the sign of r's side of the line p -> q
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (
            r[..., 0] - p[..., 0]
        )

    for i in range(n - 2):
        j = np.arange(i + 2, n - 1 if i == 0 else n)  # not a neighbour: they share a corner
        if j.size == 0:
            continue
        c, d = a[j], b[j]
        hit = (side(a[i], b[i], c) * side(a[i], b[i], d) < 0) & (
            side(c, d, a[i]) * side(c, d, b[i]) < 0
        )
        if hit.any():
            return i, int(j[np.argmax(hit)])
    return None


def _parse_terrain(item, path, index, room):
    k = _keys(TerrainKeys, item, path)
    has_points = k.points is not None
    if has_points == (k.center is not None):
        raise WorldConfigError(
            f"{path} needs either points = [[x, y], ...] (a polygon) or "
            f"center = [x, y] with size = [length, width] (a rectangle)"
        )
    if has_points:
        polygon = k.points
        crossing = _crossing_edges(polygon)
        if crossing is not None:
            # The physics and the raster would take it by the even-odd rule, the 3D
            # renderer's triangles as something else: only a simple polygon means one patch.
            n = len(polygon)
            i, j = crossing
            raise WorldConfigError(
                f"{path}.points cross themselves: the edge points[{i}] -> [{(i + 1) % n}] "
                f"crosses points[{j}] -> [{(j + 1) % n}]; list the corners in order round "
                f"the patch"
            )
        area = 0.5 * abs(
            sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1]))
        )
        if area < 1e-4:
            raise WorldConfigError(f"{path}.points encloses no area (the points are on a line)")
    else:
        shape = FurnitureConfig("", "box", k.center, k.size, k.angle_deg * DEG, 0.0, (0, 0, 0))
        polygon = tuple(tuple(c) for c in shape.corners())
    inside = [
        (x, y) for x, y in polygon if -1e-9 <= x <= room[0] + 1e-9 and -1e-9 <= y <= room[1] + 1e-9
    ]
    if not inside:
        raise WorldConfigError(f"{path} lies outside the room (0..{room[0]:g} x 0..{room[1]:g} m)")
    name = k.name or f"terrain{index}"
    return TerrainPatch(
        name, polygon, k.friction, k.slope_deg * DEG, k.slope_dir_deg * DEG, k.color
    )


def _unique(names, path):
    for i, name in enumerate(names):
        if name in names[:i]:
            raise WorldConfigError(f"{path}[{i}].name {name!r} is used twice")


def _parse_room(section):
    k = _keys(RoomKeys, section, "room")
    room = (k.width, k.depth)
    furniture = tuple(
        _parse_furniture(item, f"room.furniture[{i}]", i)
        for i, item in enumerate(_raw(section, "furniture"))
    )
    terrain = tuple(
        _parse_terrain(item, f"room.terrain[{i}]", i, room)
        for i, item in enumerate(_raw(section, "terrain"))
    )
    lines = tuple(
        _parse_line(item, f"room.lines[{i}]", i, room)
        for i, item in enumerate(_raw(section, "lines"))
    )
    _unique([line.name for line in lines], "room.lines")
    _unique([f.name for f in furniture], "room.furniture")
    for i, f in enumerate(furniture):
        x, y = f.center
        if not (0 < x < k.width and 0 < y < k.depth):
            raise WorldConfigError(
                f"room.furniture[{i}].center {_fmt(f.center)} is outside "
                f"the room (0..{k.width:g} x 0..{k.depth:g} m)"
            )
        _check_below_ceiling(f"room.furniture[{i}].height", f.height, k.height)
    return RoomConfig(
        k.width,
        k.depth,
        k.height,
        k.wall_color,
        k.floor_color,
        k.ceiling_color,
        furniture,
        terrain,
        lines,
    )


def _raw(section, key):
    """The raw tables of an array of tables (the model has checked them): each is parsed
    again by its own parser, which knows its index and the room."""
    return (section or {}).get(key, [])


def _inside(point, radius, room):
    x, y = point
    return radius <= x <= room.width - radius and radius <= y <= room.depth - radius


#: Robot keys that override the robot model's value of the same name.
_SPEC_KEYS = (
    "mass",
    "body_radius",
    "wheel_radius",
    "wheel_separation",
    "max_wheel_dps",
    "wheel_accel_dps2",
    "traction_force",
    "camera_height",
    "camera_forward",
    "com_height",
    "support_half_length",
    "support_half_width",
    "motor_step_response",
)


def start_name(default):
    """How an error names the robot's start: a default the user never wrote is said to be one."""
    return "the default robot.start (the scenario sets none)" if default else "robot.start"


def _parse_robot(section, room):
    k = _keys(RobotKeys, section, "robot")
    base = ROBOT_MODELS[k.model]
    # Half a metre short of mid-room at most: the default person's first waypoint, mid-room,
    # stays ahead of the robot, clear of it, in a narrow room too.
    start = k.start or (min(1.5, room.width / 2 - 0.5), room.depth / 2)
    fields = {
        key: getattr(base, key) if getattr(k, key) is None else getattr(k, key)
        for key in _SPEC_KEYS
    }
    fields["traction_torque"] = (
        fields["traction_force"] * fields["wheel_separation"] / 2
        if k.traction_torque is None
        else k.traction_torque
    )
    tilt_deg = base.camera_tilt / DEG if k.camera_tilt_deg is None else k.camera_tilt_deg
    fields["camera_tilt"] = tilt_deg * DEG
    uncertainty = Uncertainty(
        motor_gain_error=k.motor_gain_error,
        motor_noise_dps=k.motor_noise_dps,
        slip_rate_hz=k.slip_rate_hz,
        slip_duration_s=k.slip_duration_s,
        slip_traction=k.slip_traction,
    )
    if not fields["camera_height"] < room.height:
        # The renderer draws from between the floor and the ceiling only.
        raise WorldConfigError(
            f"robot.camera_height must be below the ceiling (room.height = {room.height:g} m), "
            f"got {fields['camera_height']:g}"
        )
    spec = base.with_overrides(**fields)
    if not _inside(start, spec.body_radius, room):
        raise WorldConfigError(
            f"{start_name(k.start is None)} {_fmt(start)} puts the robot (radius "
            f"{spec.body_radius:g} m) outside the room (0..{room.width:g} x 0..{room.depth:g} m)"
            + ("; set robot.start" if k.start is None else "")
        )
    return RobotConfig(spec, tuple(start), k.heading_deg * DEG, uncertainty, k.start is None)


def default_people(room):
    """The people of a world whose file gives none: one target walking a loop."""
    w, d = room.width, room.depth
    return [
        {
            "name": "target",
            "target": True,
            "waypoints": [[0.5 * w, 0.5 * d], [0.75 * w, 0.75 * d], [0.8 * w, 0.25 * d]],
            "speed": 0.4,
            "pause": 2.0,
            "loop": True,
            "start_delay": 1.0,
        }
    ]


def _check_below_ceiling(key, height, ceiling):
    """Nothing may stand taller than the room: the raster renderer cuts it at the ceiling,
    the 3D one would draw it through, and the two would see different images."""
    if height > ceiling:
        raise WorldConfigError(
            f"{key} must be at most the ceiling's (room.height = {ceiling:g} m), got {height:g}"
        )


def _parse_person(item, path, index, room):
    k = _keys(PersonKeys, item, path)
    _check_below_ceiling(f"{path}.height", k.height, room.height)
    waypoints = k.waypoints
    if isinstance(k.pause, tuple):
        if len(k.pause) != len(waypoints):
            raise WorldConfigError(
                f"{path}.pause must be one number or one per waypoint ({len(waypoints)}), "
                f"got {len(k.pause)} values"
            )
        pauses = k.pause
    else:
        pauses = (k.pause,) * len(waypoints)
    for i, p in enumerate(waypoints):
        if not _inside(p, k.radius, room):
            raise WorldConfigError(
                f"{path}.waypoints[{i}] {_fmt(p)} puts the person (radius {k.radius:g} m) "
                f"outside the room (0..{room.width:g} x 0..{room.depth:g} m)"
            )
    return PersonConfig(
        k.name or f"person{index}",
        index == 0 if k.target is None else k.target,
        waypoints,
        k.speed,
        k.speed_jitter,
        pauses,
        k.loop,
        k.start_delay,
        k.yield_gap,
        k.radius,
        k.height,
        k.shirt_color,
        k.trousers_color,
        k.skin_color,
    )


def _parse_people(section, room):
    if section is None:
        try:
            return _parse_people(default_people(room), room)
        except WorldConfigError as e:
            raise WorldConfigError(
                f"the default person (the scenario has no [[people]]) does not fit the "
                f"{room.width:g} x {room.depth:g} m room: {e}; give [[people]] with waypoints "
                "inside it"
            ) from None
    if not isinstance(section, list):
        raise WorldConfigError(
            f"people must be an array of tables ([[people]]), got {show(section)}"
        )
    people = tuple(_parse_person(item, f"people[{i}]", i, room) for i, item in enumerate(section))
    _unique([p.name for p in people], "people")
    targets = [i for i, p in enumerate(people) if p.target]
    if len(targets) > 1:
        raise WorldConfigError(
            f"people[{targets[1]}].target: only one person can be the target "
            f"(people[{targets[0]}] already is)"
        )
    return people


def _parse_lighting(section):
    k = _keys(LightingKeys, section, "lighting")
    if math.hypot(*k.direction) < 1e-3:
        raise WorldConfigError(
            f"lighting.direction must have a length of at least 0.001, got {_fmt(k.direction)}"
        )
    return LightingConfig(k.ambient, k.intensity, k.direction, k.keyframes, k.interpolation)


def parse_world_config(cfg):
    """Validate a scenario's world sections and fill in defaults.

    Parameters
    ----------
    cfg : dict or None
        Any of the sections ``room``, ``robot``, ``people``, ``lighting``; missing sections
        take their defaults (an empty dict gives the default world).

    Returns
    -------
    WorldConfig

    Raises
    ------
    WorldConfigError
        Naming the key path, e.g. ``robot.mass must be > 0, got -1``.
    """
    if cfg is None:
        cfg = {}
    if not isinstance(cfg, dict):
        raise WorldConfigError(f"the world configuration must be a table, got {show(cfg)}")
    for key in cfg:
        if key not in WORLD_SECTIONS:
            close = difflib.get_close_matches(str(key), WORLD_SECTIONS, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise WorldConfigError(
                f"{key} is not a world section{hint}; the sections are " + ", ".join(WORLD_SECTIONS)
            )
    room = _parse_room(cfg.get("room"))
    robot = _parse_robot(cfg.get("robot"), room)
    people = _parse_people(cfg.get("people"), room)
    lighting = _parse_lighting(cfg.get("lighting"))
    return WorldConfig(room, robot, people, lighting)
