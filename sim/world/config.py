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

from fpga_robotics.hw.errors import UserError

from .kinematics import DEG
from .markings import FloorLine
from .robots import ROBOT_MODELS
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
]

#: The scenario sections that describe the world.
WORLD_SECTIONS = ("room", "robot", "people", "lighting")

#: The latest time (s) a world description may name (keyframes, start delays): one day.
MAX_TIME = 86400.0

DEFAULT_SHIRT = (0.85, 0.1, 0.1)
DEFAULT_TROUSERS = (0.15, 0.15, 0.22)
DEFAULT_SKIN = (0.87, 0.68, 0.56)
#: Red-brown wood: the divider that the published colour filter mistook for a red shirt.
DIVIDER_WOOD = (0.55, 0.27, 0.15)
_BOX_COLOR = (0.45, 0.42, 0.38)
_WALL_COLOR = (0.8, 0.78, 0.72)
_FLOOR_COLOR = (0.55, 0.55, 0.5)
_CEILING_COLOR = (0.9, 0.9, 0.9)


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


def _show(value):
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, (list, tuple)):
        return f"{list(value)!r} (array)"
    return f"{value!r} ({type(value).__name__})"


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check_number(value, path, *, gt=None, ge=None, le=None, unit=""):
    """Return ``value`` as a float if it is a finite number within the bounds."""
    finite = _is_number(value) and math.isfinite(value)
    checks = [(f"> {b:g}", finite and value > b) for b in (gt,) if b is not None]
    checks += [(f">= {b:g}", finite and value >= b) for b in (ge,) if b is not None]
    checks += [(f"<= {b:g}", finite and value <= b) for b in (le,) if b is not None]
    if not finite:
        what = "a number" + (f" in {unit}" if unit else "")
        if checks:
            what += " " + " and ".join(text for text, _ in checks)
        raise WorldConfigError(f"{path} must be {what}, got {_show(value)}")
    for text, ok in checks:
        if not ok:
            raise WorldConfigError(f"{path} must be {text}, got {value!r}")
    return float(value)


def _fmt(point):
    return "[" + ", ".join(f"{c:g}" for c in point) + "]"


def _check_vector(value, path, n, what, **bounds):
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise WorldConfigError(f"{path} must be {what}, got {_show(value)}")
    return tuple(_check_number(v, f"{path}[{i}]", **bounds) for i, v in enumerate(value))


class _Table:
    """Reads the keys of one table and reports the ones never read as unknown."""

    def __init__(self, table, path):
        if table is None:
            table = {}
        if not isinstance(table, dict):
            raise WorldConfigError(f"{path} must be a table, got {_show(table)}")
        self.table = table
        self.path = path
        self.known = []

    def key(self, key):
        return f"{self.path}.{key}" if self.path else key

    def has(self, key):
        return key in self.table

    def raw(self, key, default=None):
        self.known.append(key)
        return self.table.get(key, default)

    def number(self, key, default, **bounds):
        if key not in self.table:
            self.known.append(key)
            return default
        return _check_number(self.raw(key), self.key(key), **bounds)

    def boolean(self, key, default):
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise WorldConfigError(f"{self.key(key)} must be true or false, got {_show(value)}")
        return value

    def string(self, key, default, choices=None):
        value = self.raw(key, default)
        if not isinstance(value, str) or not value:
            raise WorldConfigError(
                f"{self.key(key)} must be a non-empty string, got {_show(value)}"
            )
        if choices is not None and value not in choices:
            options = ", ".join(repr(c) for c in choices)
            raise WorldConfigError(f"{self.key(key)} must be one of {options}, got {value!r}")
        return value

    def color(self, key, default):
        if key not in self.table:
            self.known.append(key)
            return tuple(default)
        return _check_vector(
            self.raw(key), self.key(key), 3, "a colour [r, g, b] with each in 0..1", ge=0, le=1
        )

    def point(self, key, default):
        if key not in self.table:
            self.known.append(key)
            return default
        return _check_vector(self.raw(key), self.key(key), 2, "a point [x, y] in m")

    def finish(self):
        unknown = [k for k in self.table if k not in self.known]
        if unknown:
            key = unknown[0]
            close = difflib.get_close_matches(str(key), self.known, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            known = ", ".join(self.known)
            raise WorldConfigError(f"{self.key(key)} is not a known key{hint}; known keys: {known}")


def _parse_furniture(item, path, index):
    t = _Table(item, path)
    name = t.string("name", f"furniture{index}")
    kind = t.string("type", "box", choices=("box", "divider"))
    if not t.has("center"):
        raise WorldConfigError(f"{t.key('center')} is required: the centre [x, y] in m")
    center = t.point("center", None)
    divider = kind == "divider"
    size = t.raw("size", (1.5, 0.03) if divider else (1.0, 0.6))
    size = _check_vector(size, t.key("size"), 2, "[length, width] in m", ge=0.01, le=100)
    angle = t.number("angle_deg", 0.0, ge=-360, le=360) * DEG
    height = t.number("height", 1.6 if divider else 0.75, gt=0, le=10, unit="m")
    color = t.color("color", DIVIDER_WOOD if divider else _BOX_COLOR)
    present_until = t.number("present_until", None, gt=0, le=MAX_TIME, unit="s")
    t.finish()
    return FurnitureConfig(name, kind, center, size, angle, height, color, present_until)


#: Floor markings' default colour: black electrical tape.
_LINE_COLOR = (0.0, 0.0, 0.0)


def _parse_line(item, path, index, room):
    t = _Table(item, path)
    name = t.string("name", f"line{index}")
    points = t.raw("points")
    closed = t.boolean("closed", False)
    least = 3 if closed else 2
    if not isinstance(points, list) or len(points) < least:
        raise WorldConfigError(
            f"{t.key('points')} must be an array of at least {least} points [x, y] "
            f"({'a closed' if closed else 'an open'} line), got "
            f"{_show(points) if points is not None else 'nothing'}"
        )
    centreline = tuple(
        _check_vector(p, f"{t.key('points')}[{i}]", 2, "a point [x, y] in m")
        for i, p in enumerate(points)
    )
    width = t.number("width", 0.019, gt=0, le=1, unit="m")
    color = t.color("color", _LINE_COLOR)
    t.finish()
    w, d = room
    for i, (x, y) in enumerate(centreline):
        if not (0 <= x <= w and 0 <= y <= d):
            raise WorldConfigError(
                f"{t.key('points')}[{i}] {_fmt((x, y))} is outside the room (0..{w:g} x 0..{d:g} m)"
            )
    line = FloorLine(name, centreline, width, color, closed)
    if line.length < 1e-6:
        raise WorldConfigError(f"{t.key('points')} has no length (all the points are the same)")
    return line


def _parse_terrain(item, path, index, room):
    t = _Table(item, path)
    name = t.string("name", f"terrain{index}")
    has_points, has_center = t.has("points"), t.has("center")
    if has_points == has_center:
        raise WorldConfigError(
            f"{path} needs either points = [[x, y], ...] (a polygon) or "
            f"center = [x, y] with size = [length, width] (a rectangle)"
        )
    if has_points:
        points = t.raw("points")
        if not isinstance(points, list) or len(points) < 3:
            raise WorldConfigError(
                f"{t.key('points')} must be an array of at least 3 points "
                f"[x, y], got {_show(points)}"
            )
        polygon = tuple(
            _check_vector(p, f"{t.key('points')}[{i}]", 2, "a point [x, y] in m")
            for i, p in enumerate(points)
        )
        area = 0.5 * abs(
            sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(polygon, polygon[1:] + polygon[:1]))
        )
        if area < 1e-4:
            raise WorldConfigError(f"{t.key('points')} encloses no area (the points are on a line)")
    else:
        center = t.point("center", None)
        size = _check_vector(
            t.raw("size", (1.0, 1.0)), t.key("size"), 2, "[length, width] in m", ge=0.01, le=100
        )
        angle = t.number("angle_deg", 0.0, ge=-360, le=360) * DEG
        shape = FurnitureConfig(name, "box", center, size, angle, 0.0, (0, 0, 0))
        polygon = tuple(tuple(c) for c in shape.corners())
    friction = t.number("friction", 1.0, ge=0.01, le=10)
    slope = t.number("slope_deg", 0.0, ge=0, le=45) * DEG
    slope_dir = t.number("slope_dir_deg", 0.0, ge=-360, le=360) * DEG
    # No colour: the patch is not drawn (a wet floor looks like the floor).
    color = t.color("color", (0.0, 0.0, 0.0)) if t.has("color") else t.raw("color")
    t.finish()
    inside = [
        (x, y) for x, y in polygon if -1e-9 <= x <= room[0] + 1e-9 and -1e-9 <= y <= room[1] + 1e-9
    ]
    if not inside:
        raise WorldConfigError(f"{path} lies outside the room (0..{room[0]:g} x 0..{room[1]:g} m)")
    return TerrainPatch(name, polygon, friction, slope, slope_dir, color)


def _parse_room(section):
    t = _Table(section, "room")
    width = t.number("width", 8.0, gt=0.5, le=100, unit="m")
    depth = t.number("depth", 6.0, gt=0.5, le=100, unit="m")
    height = t.number("height", 2.5, gt=0.2, le=20, unit="m")
    wall_color = t.color("wall_color", _WALL_COLOR)
    floor_color = t.color("floor_color", _FLOOR_COLOR)
    ceiling_color = t.color("ceiling_color", _CEILING_COLOR)
    items = t.raw("furniture", [])
    if not isinstance(items, list):
        raise WorldConfigError(
            f"room.furniture must be an array of tables ([[room.furniture]]), got {_show(items)}"
        )
    furniture = tuple(
        _parse_furniture(item, f"room.furniture[{i}]", i) for i, item in enumerate(items)
    )
    patches = t.raw("terrain", [])
    if not isinstance(patches, list):
        raise WorldConfigError(
            f"room.terrain must be an array of tables ([[room.terrain]]), got {_show(patches)}"
        )
    terrain = tuple(
        _parse_terrain(item, f"room.terrain[{i}]", i, (width, depth))
        for i, item in enumerate(patches)
    )
    raw_lines = t.raw("lines", [])
    if not isinstance(raw_lines, list):
        raise WorldConfigError(
            f"room.lines must be an array of tables ([[room.lines]]), got {_show(raw_lines)}"
        )
    lines = tuple(
        _parse_line(item, f"room.lines[{i}]", i, (width, depth)) for i, item in enumerate(raw_lines)
    )
    line_names = [line.name for line in lines]
    for i, name in enumerate(line_names):
        if name in line_names[:i]:
            raise WorldConfigError(f"room.lines[{i}].name {name!r} is used twice")
    names = [f.name for f in furniture]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise WorldConfigError(f"room.furniture[{i}].name {name!r} is used twice")
    for i, f in enumerate(furniture):
        x, y = f.center
        if not (0 < x < width and 0 < y < depth):
            raise WorldConfigError(
                f"room.furniture[{i}].center {_fmt(f.center)} is outside "
                f"the room (0..{width:g} x 0..{depth:g} m)"
            )
    t.finish()
    return RoomConfig(
        width, depth, height, wall_color, floor_color, ceiling_color, furniture, terrain, lines
    )


def _inside(point, radius, room):
    x, y = point
    return radius <= x <= room.width - radius and radius <= y <= room.depth - radius


def _parse_robot(section, room):
    t = _Table(section, "robot")
    model = t.string("model", "turtlebot2", choices=tuple(ROBOT_MODELS))
    base = ROBOT_MODELS[model]
    start = t.point("start", (min(1.5, room.width / 2), room.depth / 2))
    heading = t.number("heading_deg", 0.0, ge=-360, le=360) * DEG
    fields = {}
    for key, bounds in (
        ("mass", {"ge": 0.05, "le": 1000, "unit": "kg"}),
        ("body_radius", {"ge": 0.02, "le": 2, "unit": "m"}),
        ("wheel_radius", {"ge": 0.005, "le": 1, "unit": "m"}),
        ("wheel_separation", {"ge": 0.02, "le": 3, "unit": "m"}),
        ("max_wheel_dps", {"gt": 0, "le": 100000, "unit": "deg/s"}),
        ("wheel_accel_dps2", {"gt": 0, "le": 1e6, "unit": "deg/s^2"}),
        ("traction_force", {"gt": 0, "le": 1e5, "unit": "N"}),
        ("camera_height", {"gt": 0, "le": 5, "unit": "m"}),
        ("camera_forward", {"ge": -2, "le": 2, "unit": "m"}),
    ):
        fields[key] = t.number(key, getattr(base, key), **bounds)
    fields["traction_torque"] = t.number(
        "traction_torque",
        fields["traction_force"] * fields["wheel_separation"] / 2,
        gt=0,
        le=1e5,
        unit="N m",
    )
    fields["camera_tilt"] = t.number("camera_tilt_deg", base.camera_tilt / DEG, ge=-85, le=85) * DEG
    for key, bounds in (
        ("com_height", {"gt": 0, "le": 5, "unit": "m"}),
        ("support_half_length", {"gt": 0, "le": 5, "unit": "m"}),
    ):
        fields[key] = t.number(key, getattr(base, key), **bounds)
    # None (the presets' value): commands are ramped, a jump never tips the robot.
    fields["motor_step_response"] = t.number(
        "motor_step_response", base.motor_step_response, gt=0, le=10, unit="s"
    )
    uncertainty = Uncertainty(
        motor_gain_error=t.number("motor_gain_error", 0.0, ge=0, le=0.9),
        motor_noise_dps=t.number("motor_noise_dps", 0.0, ge=0, le=10000, unit="deg/s"),
        slip_rate_hz=t.number("slip_rate_hz", 0.0, ge=0, le=100, unit="1/s"),
        slip_duration_s=t.number("slip_duration_s", 0.2, gt=0, le=60, unit="s"),
        slip_traction=t.number("slip_traction", 0.2, ge=0.01, le=1),
    )
    t.finish()
    if not fields["camera_height"] < room.height:
        # The renderer draws from between the floor and the ceiling only.
        raise WorldConfigError(
            f"robot.camera_height must be below the ceiling (room.height = {room.height:g} m), "
            f"got {fields['camera_height']:g}"
        )
    spec = base.with_overrides(**fields)
    if not _inside(start, spec.body_radius, room):
        raise WorldConfigError(
            f"robot.start {_fmt(start)} puts the robot (radius {spec.body_radius:g} m) outside "
            f"the room (0..{room.width:g} x 0..{room.depth:g} m)"
        )
    return RobotConfig(spec, tuple(start), heading, uncertainty)


def _default_people(room):
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


def _parse_person(item, path, index, room):
    t = _Table(item, path)
    name = t.string("name", f"person{index}")
    target = t.boolean("target", index == 0)
    raw = t.raw("waypoints")
    if raw is None:
        raise WorldConfigError(f"{path}.waypoints is required: an array of [x, y] points in m")
    if not isinstance(raw, list) or not raw:
        raise WorldConfigError(
            f"{path}.waypoints must be a non-empty array of [x, y] points, got {_show(raw)}"
        )
    waypoints = tuple(
        _check_vector(p, f"{path}.waypoints[{i}]", 2, "a point [x, y] in m")
        for i, p in enumerate(raw)
    )
    speed = t.number("speed", 0.5, gt=0, le=5, unit="m/s")
    jitter = t.number("speed_jitter", 0.0, ge=0, le=0.9)
    pause = t.raw("pause", 1.0)
    if isinstance(pause, list):
        if len(pause) != len(waypoints):
            raise WorldConfigError(
                f"{path}.pause must be one number or one per waypoint ({len(waypoints)}), "
                f"got {len(pause)} values"
            )
        pauses = tuple(
            _check_number(p, f"{path}.pause[{i}]", ge=0, le=3600, unit="s")
            for i, p in enumerate(pause)
        )
    else:
        pauses = (_check_number(pause, f"{path}.pause", ge=0, le=3600, unit="s"),) * len(waypoints)
    loop = t.boolean("loop", True)
    start_delay = t.number("start_delay", 0.0, ge=0, le=MAX_TIME, unit="s")
    yield_gap = t.number("yield_gap", 0.0, ge=0, le=5, unit="m")
    radius = t.number("radius", 0.2, ge=0.05, le=1, unit="m")
    height = t.number("height", 1.75, ge=0.5, le=2.5, unit="m")
    shirt = t.color("shirt_color", DEFAULT_SHIRT)
    trousers = t.color("trousers_color", DEFAULT_TROUSERS)
    skin = t.color("skin_color", DEFAULT_SKIN)
    t.finish()
    for i, p in enumerate(waypoints):
        if not _inside(p, radius, room):
            raise WorldConfigError(
                f"{path}.waypoints[{i}] {_fmt(p)} puts the person (radius {radius:g} m) outside "
                f"the room (0..{room.width:g} x 0..{room.depth:g} m)"
            )
    return PersonConfig(
        name,
        target,
        waypoints,
        speed,
        jitter,
        pauses,
        loop,
        start_delay,
        yield_gap,
        radius,
        height,
        shirt,
        trousers,
        skin,
    )


def _parse_people(section, room):
    if section is None:
        section = _default_people(room)
    if not isinstance(section, list):
        raise WorldConfigError(
            f"people must be an array of tables ([[people]]), got {_show(section)}"
        )
    people = tuple(_parse_person(item, f"people[{i}]", i, room) for i, item in enumerate(section))
    names = [p.name for p in people]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise WorldConfigError(f"people[{i}].name {name!r} is used twice")
    targets = [i for i, p in enumerate(people) if p.target]
    if len(targets) > 1:
        raise WorldConfigError(
            f"people[{targets[1]}].target: only one person can be the target "
            f"(people[{targets[0]}] already is)"
        )
    return people


def _parse_lighting(section):
    t = _Table(section, "lighting")
    ambient = t.number("ambient", 0.6, ge=0, le=2)
    intensity = t.number("intensity", 0.5, ge=0, le=2)
    direction = t.raw("direction", [1.0, 0.5, -1.0])
    direction = _check_vector(
        direction,
        "lighting.direction",
        3,
        "a vector [dx, dy, dz], each -1000..1000",
        ge=-1000,
        le=1000,
    )
    if math.hypot(*direction) < 1e-3:
        raise WorldConfigError(
            f"lighting.direction must have a length of at least 0.001, got {_fmt(direction)}"
        )
    raw = t.raw("keyframes", [])
    if not isinstance(raw, list):
        raise WorldConfigError(
            f"lighting.keyframes must be an array of [t, ambient, intensity], got {_show(raw)}"
        )
    keyframes = []
    for i, k in enumerate(raw):
        p = f"lighting.keyframes[{i}]"
        if not isinstance(k, (list, tuple)) or len(k) != 3:
            raise WorldConfigError(f"{p} must be [t, ambient, intensity], got {_show(k)}")
        frame = (
            _check_number(k[0], f"{p}[0] (t)", ge=0, le=MAX_TIME, unit="s"),
            _check_number(k[1], f"{p}[1] (ambient)", ge=0, le=2),
            _check_number(k[2], f"{p}[2] (intensity)", ge=0, le=2),
        )
        if keyframes and frame[0] < keyframes[-1][0]:
            raise WorldConfigError(
                f"{p}[0] (t) must not be earlier than the previous keyframe's "
                f"({keyframes[-1][0]:g} s), got {frame[0]:g}"
            )
        keyframes.append(frame)
    interpolation = t.string("interpolation", "linear", choices=("linear", "step"))
    t.finish()
    return LightingConfig(ambient, intensity, direction, tuple(keyframes), interpolation)


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
        raise WorldConfigError(f"the world configuration must be a table, got {_show(cfg)}")
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
