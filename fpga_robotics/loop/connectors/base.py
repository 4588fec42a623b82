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

from pydantic_core import PydanticCustomError

from fpga_robotics.hw.errors import UserError
from fpga_robotics.sim.world.schema import KeyModel, Number, check_of, validate

__all__ = [
    "CONNECTORS",
    "MOUNT_KEYS",
    "Connector",
    "ConnectorError",
    "ConnectorKeys",
    "Mount",
    "MountKeys",
    "Pin",
    "PinIO",
    "check_number",
    "connector_class",
    "parse_mount",
    "register",
    "validate_value",
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


class ConnectorKeys(KeyModel):
    """The keys of a connector kind's table (besides ``kind``, ``name``, ``ports`` and the
    mount): a kind declares its own subclass, one field per key (``Number(..., style=
    "bounds")`` for the connectors' messages), and sets it as ``Connector.keys``."""

    @classmethod
    def unknown_key(cls, path, key):
        where = path.rpartition(".")[0]
        kind = f" for a {cls.label!r} connector" if cls.label else ""
        return (
            f"{where}: unknown key {key!r}{kind}; its keys: {', '.join(cls.key_names())} "
            f"(and the mount: {', '.join(MOUNT_KEYS)})"
        )


class Connector:
    """Base class of every connector kind. Subclasses set ``kind``, ``pins``, ``watch``,
    declare their keys (``keys``, a ``ConnectorKeys`` model, or their own ``parse``) and
    implement the hooks they need."""

    #: The registry key, the scenario's ``kind = "..."``.
    kind: ClassVar[str] = ""
    #: ``"sensor"`` (world to design) or ``"actuator"`` (design to world).
    role: ClassVar[str] = "sensor"
    #: role name -> Pin.
    pins: ClassVar[dict] = {}
    #: Design outputs (pin roles) whose change calls ``on_change``.
    watch: ClassVar[tuple] = ()
    #: The kind's scenario keys (a ``ConnectorKeys`` subclass); None: no keys of its own.
    keys: ClassVar[type | None] = None

    def __init__(self, name, mount, params, *, world, rng):
        self.name = name
        self.mount = mount
        self.params = params
        self.world = world
        self.rng = rng

    @classmethod
    def parse(cls, table, where):
        """Validate the kind's parameters in ``table`` (the scenario table without ``kind``,
        ``name`` and the mount keys) against ``keys``; return the params object (the
        validated ``keys`` model; override ``params_of`` for another). Raise
        ``ConnectorError`` naming ``where`` (e.g. ``robot.sensors[0]``) and the key."""
        if cls.keys is None:
            if table:
                raise ConnectorError(
                    f"{where}: unknown key {min(table)!r} for a {cls.kind!r} connector"
                )
            return None
        return cls.params_of(validate(cls.keys, table, where, ConnectorError))

    @classmethod
    def check_run(cls, params, mount, where, sim, room):
        """Check the parsed table against the rest of the scenario, at load: ``sim`` (the
        ``[sim]`` config, its timing resolved: ``clock_hz``) and ``room`` (the room's
        config: ``height``). Raise ``ConnectorError`` naming ``where``; by default nothing
        to check."""

    @classmethod
    def params_of(cls, keys):
        """The params object of the validated keys (by default the keys model itself)."""
        return keys

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


class MountKeys(KeyModel):
    """Where a connector sits: ``forward``, ``left`` of the robot's centre and ``height``
    above the floor (m), ``yaw_deg`` from the robot's heading (left positive)."""

    forward: Number(ge=-2, le=2, unit="m", style="bounds") = 0.0
    left: Number(ge=-2, le=2, unit="m", style="bounds") = 0.0
    height: Number(ge=0, le=3, unit="m", style="bounds") = 0.0
    yaw_deg: Number(ge=-360, le=360, style="bounds") = 0.0


def refuse_above_ceiling(mount, where, room):
    """A ranging sensor mounted at or above the ceiling would look over the walls."""
    if not mount.height < room.height:
        raise ConnectorError(
            f"{where}.height must be below the ceiling (room.height = {room.height:g} m), "
            f"got {mount.height:g}"
        )


def check_number(table, key, default, where, *, lo, hi, unit="", lo_open=False, note=""):
    """``table[key]`` (or ``default``) as a float within ``lo..hi`` (``lo`` excluded with
    ``lo_open``); a ``ConnectorError`` naming ``where.key`` otherwise (with ``note``, why
    the upper bound, when above it)."""
    bound = {"gt": lo} if lo_open else {"ge": lo}
    check = check_of(Number(**bound, le=hi, unit=unit, style="bounds", note=note))
    return validate_value(check, table.get(key, default), f"{where}.{key}")


def refuse_unknown_keys(table, known, where, kind, listed=None):
    """A ``ConnectorError`` naming the first key of ``table`` not in ``known`` and the keys a
    ``kind`` table holds (``listed``, or ``known`` joined)."""
    unknown = sorted(k for k in table if k not in known)
    if unknown:
        article = "an" if kind[0] in "aeiou" else "a"
        raise ConnectorError(
            f"{where}: unknown key {unknown[0]!r} for {article} {kind!r} connector; its keys: "
            f"{listed or ', '.join(known)}"
        )


def check_numbers(table, keys, defaults, where):
    """``{key: check_number(...)}`` for ``keys`` ``{key: (lo, hi, unit, lo_open[, note])}``,
    each defaulting to the attribute of ``defaults`` of its name."""
    return {
        key: check_number(
            table,
            key,
            getattr(defaults, key),
            where,
            lo=lo,
            hi=hi,
            unit=unit,
            lo_open=lo_open,
            note=note[0] if note else "",
        )
        for key, (lo, hi, unit, lo_open, *note) in keys.items()
    }


def validate_value(check, value, path):
    """``check(value)`` (a key type's check, ``sim.world.schema.check_of``); a
    ``ConnectorError`` naming ``path`` otherwise."""
    try:
        return check(value)
    except PydanticCustomError as exc:
        raise ConnectorError(f"{path}{exc.context.get('sub', '')} {exc.message()}") from None


def parse_mount(table, where):
    """Split a connector table into its ``Mount`` (keys ``MOUNT_KEYS``: m, m, m, degrees)
    and the rest (a new dict); a ``ConnectorError`` naming ``where`` for a bad value."""
    rest = {k: v for k, v in table.items() if k not in MOUNT_KEYS}
    keys = validate(
        MountKeys, {k: v for k, v in table.items() if k in MOUNT_KEYS}, where, ConnectorError
    )
    mount = Mount(
        forward=keys.forward, left=keys.left, height=keys.height, yaw=math.radians(keys.yaw_deg)
    )
    return mount, rest


def register(cls):
    """Class decorator: make ``cls`` available as ``kind = cls.kind`` in scenarios."""
    if not cls.kind or cls.kind in CONNECTORS:
        raise ValueError(f"connector kind {cls.kind!r} is empty or taken")
    if cls.keys is not None and not cls.keys.label:
        cls.keys.label = cls.kind  # its unknown-key message names the kind
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
