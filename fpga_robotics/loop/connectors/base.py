"""Connectors as an API: what a design's pins see of the world and what they do to it.

A connector is a world-side model (what it measures in the world, or what it does to the
world) plus the design pins it binds to. Scenarios declare connectors in
``[[robot.sensors]]`` and ``[[robot.actuators]]`` tables (``kind``, ``name``, the mount and
the kind's parameters); a design binds each connector pin to one of its ports (by the
design's own binding table or a port map). ``register`` adds a kind; docs/connectors.md walks
through writing one.

In real-clock timing (``[sim] timing = "real_clock"``) the closed loop calls, for every
connector, ``start`` once after the design's reset, then for every physics step
``before_step`` (drive the inputs for the coming step: values now or at exact future edges)
and ``after_step`` (act on the world), and ``on_change`` whenever one of the connector's
``watch`` pins (design outputs) changes, at the edge where it changed. Connectors talk to the
design only through ``PinIO``: pins by their role name, edges of the design clock.
"""

import math
from dataclasses import dataclass
from typing import ClassVar

from fpga_robotics.hw.errors import UserError

__all__ = [
    "CONNECTORS",
    "MOUNT_KEYS",
    "Connector",
    "ConnectorError",
    "Mount",
    "Pin",
    "PinIO",
    "check_number",
    "connector_class",
    "parse_mount",
    "register",
]

#: kind -> Connector subclass.
CONNECTORS = {}


class ConnectorError(UserError, ValueError):
    """A connector table that is malformed (unknown kind, bad parameter): a usage error."""


@dataclass(frozen=True)
class Pin:
    """One pin of a connector, seen from the design: ``"in"`` the design reads it, ``"out"``
    the design drives it."""

    direction: str
    width: int = 1
    signed: bool = False


@dataclass(frozen=True)
class Mount:
    """Where a connector sits on the robot: ``forward`` and ``left`` of the robot's centre
    (m), ``height`` above the floor (m), ``yaw`` from the robot's heading (rad, left
    positive)."""

    forward: float = 0.0
    left: float = 0.0
    height: float = 0.0
    yaw: float = 0.0

    def world_pose(self, x, y, heading):
        """``(x, y, heading)`` of the mount in the world for a robot at ``(x, y, heading)``."""
        c, s = math.cos(heading), math.sin(heading)
        return (
            x + self.forward * c - self.left * s,
            y + self.forward * s + self.left * c,
            heading + self.yaw,
        )


class PinIO:
    """The design's pins as one connector sees them: by role name, through its binding
    (role -> design port). ``clock_hz`` maps edges to world time: edge ``e`` happens at
    ``e / clock_hz`` seconds."""

    def __init__(self, backend, binding, clock_hz):
        self.backend = backend
        self.binding = dict(binding)
        self.clock_hz = float(clock_hz)

    @property
    def cycle(self):
        """The last edge run."""
        return self.backend.cycle

    def time_of(self, edge):
        return edge / self.clock_hz

    def edge_at(self, t):
        """The first edge at or after world time ``t``."""
        return math.ceil(t * self.clock_hz - 1e-9)

    def poke(self, pin, value):
        self.backend.poke(self.binding[pin], int(value))

    def schedule(self, edge, pin, value):
        self.backend.schedule(int(edge), self.binding[pin], int(value))

    def peek(self, pin):
        return self.backend.peek(self.binding[pin])


class Connector:
    """Base class of every connector kind. Subclasses set ``kind``, ``pins``, ``watch`` and
    implement ``parse`` and the hooks they need."""

    #: The registry key, the scenario's ``kind = "..."``.
    kind: ClassVar[str] = ""
    #: ``"sensor"`` (world to design) or ``"actuator"`` (design to world).
    role: ClassVar[str] = "sensor"
    #: role name -> Pin.
    pins: ClassVar[dict] = {}
    #: Design outputs (pin roles) whose change calls ``on_change``.
    watch: ClassVar[tuple] = ()

    def __init__(self, name, mount, params, *, world, rng):
        self.name = name
        self.mount = mount
        self.params = params
        self.world = world
        self.rng = rng

    @classmethod
    def parse(cls, table, where):
        """Validate the kind's parameters in ``table`` (the scenario table without ``kind``,
        ``name`` and the mount keys); return the params object. Raise ``ConnectorError``
        naming ``where`` (e.g. ``robot.sensors[0]``) and the key."""
        if table:
            raise ConnectorError(
                f"{where}: unknown key {min(table)!r} for a {cls.kind!r} connector"
            )

    def start(self, io):
        """Called once, after the design's reset, before the first physics step."""

    def before_step(self, io, t, dt):
        """Drive the inputs for the physics step from ``t`` to ``t + dt``."""

    def on_change(self, io, pin, value, t):
        """The design output ``pin`` changed to ``value`` at edge ``io.cycle`` (time ``t``)."""

    def after_step(self, io, t):
        """The design has run up to world time ``t``: act on the world."""

    def measurement(self):
        """The latest values for the trajectory and the viewer: ``{name: float}``."""
        return {}

    def map_overlay(self):
        """What the viewer draws on the map now: ``{"points": ((x, y), ...), "states":
        (0/1 per point), "rays": (((x0, y0), (x1, y1)), ...)}`` (any key may be left out)."""
        return {}


#: The scenario keys of a connector's mount (``yaw_deg`` in degrees, as every angle in a file).
MOUNT_KEYS = ("forward", "left", "height", "yaw_deg")


def check_number(table, key, default, where, *, lo, hi, unit="", lo_open=False):
    """``table[key]`` (or ``default``) as a float within ``lo..hi`` (``lo`` excluded with
    ``lo_open``); a ``ConnectorError`` naming ``where.key`` otherwise."""
    value = table.get(key, default)
    ok = (
        isinstance(value, (int, float))
        and not isinstance(value, bool)
        and math.isfinite(value)
        and (value > lo if lo_open else value >= lo)
        and value <= hi
    )
    if not ok:
        span = f"{'>' if lo_open else '>='} {lo:g} and <= {hi:g}"
        raise ConnectorError(
            f"{where}.{key} must be a number{' in ' + unit if unit else ''} {span}, got {value!r}"
        )
    return float(value)


def parse_mount(table, where):
    """Split a connector table into its ``Mount`` (keys ``MOUNT_KEYS``: m, m, m, degrees)
    and the rest (a new dict); a ``ConnectorError`` naming ``where`` for a bad value."""
    rest = {k: v for k, v in table.items() if k not in MOUNT_KEYS}
    mount = Mount(
        forward=check_number(table, "forward", 0.0, where, lo=-2, hi=2, unit="m"),
        left=check_number(table, "left", 0.0, where, lo=-2, hi=2, unit="m"),
        height=check_number(table, "height", 0.0, where, lo=0, hi=3, unit="m"),
        yaw=math.radians(check_number(table, "yaw_deg", 0.0, where, lo=-360, hi=360)),
    )
    return mount, rest


def register(cls):
    """Class decorator: make ``cls`` available as ``kind = cls.kind`` in scenarios."""
    if not cls.kind or cls.kind in CONNECTORS:
        raise ValueError(f"connector kind {cls.kind!r} is empty or taken")
    CONNECTORS[cls.kind] = cls
    return cls


def connector_class(kind, where="robot.sensors"):
    try:
        return CONNECTORS[kind]
    except KeyError:
        raise ConnectorError(
            f"{where}: unknown connector kind {kind!r}; choose one of: "
            f"{', '.join(sorted(CONNECTORS))}"
        ) from None
