"""The built-in designs a scenario can run by name (``[design] top = "..."``): for each, how
to build it and its parameter tables. Which ports the connectors bind, and which outputs are
recorded, the designs themselves state (``designs/reference.py`` reads them).

``follow_target`` is the camera-only design of docs/contract.md (frames in, wheel speeds
out). ``follow_target_safe`` adds an HC-SR04 ultrasound driver and an interlock that stops
the wheels near an obstacle; ``follow_line`` steers by KY-033 line sensors
(docs/sensor_designs.md). A design with pins other than the camera's and the wheels' runs
in real-clock timing (``[sim] timing``).
"""

import dataclasses
import importlib
from dataclasses import dataclass, field

from fpga_robotics.hw.variants import VARIANTS, variant_params
from fpga_robotics.loop.connectors import CONNECTORS

__all__ = [
    "TOPS",
    "Top",
    "build_component",
    "connector_kinds",
    "design_tables",
    "foreign_top",
    "get_top",
    "register_top",
    "table_fields",
]


@dataclass(frozen=True)
class Top:
    name: str
    description: str
    #: The design takes the camera's pixel stream (and has FollowTarget's frame outputs).
    camera: bool
    #: Scenario sub-table ``[design.<key>]`` -> (module, params class) of its parameters.
    tables: dict = field(default_factory=dict)
    #: connector kind -> {connector pin: design port}, beyond what the component declares
    #: (its ``connectors`` attribute) and what binds by name (designs/reference.py).
    bindings: dict = field(default_factory=dict)
    #: More outputs the run records each frame: trajectory field -> design port (resolving
    #: the design fills in every output no connector reads).
    extra_outputs: dict = field(default_factory=dict)
    #: (module, class) of the component, or the class itself (a design of your own); built as
    #: ``cls(ft_params, *table params)``.
    component: object = ("fpga_robotics.hw.top", "FollowTarget")
    #: Whether the FollowTarget params (``[design]`` keys) are the first argument.
    takes_follow_target_params: bool = True
    #: Compressed timing: pixel port bundle of a further camera -> (module, class) of the
    #: frame-level model of the design's channel on it (``loop/camera_rig.py``).
    frame_channels: dict = field(default_factory=dict)


_CAMERA = {"camera": {"pixels": "pixels", "color_sel": "color_sel"}}
_WHEELS = {"wheels": {"motor_left": "motor_left", "motor_right": "motor_right"}}

TOPS = {
    "follow_target": Top(
        "follow_target", "FollowTarget: colour filter, tracker and motor controller", camera=True
    ),
    "follow_target_safe": Top(
        "follow_target_safe",
        "FollowTarget with an HC-SR04 ultrasound driver and an obstacle interlock",
        camera=True,
        tables={
            "ultrasound": ("fpga_robotics.hw.sensor_params", "UltrasoundParams"),
            "interlock": ("fpga_robotics.hw.sensor_params", "InterlockParams"),
        },
        component=("fpga_robotics.hw.safe_follow", "FollowTargetSafe"),
    ),
    "follow_line": Top(
        "follow_line",
        "FollowLine: KY-033 line sensors to wheel speeds",
        camera=False,
        tables={"line": ("fpga_robotics.hw.sensor_params", "FollowLineParams")},
        component=("fpga_robotics.hw.follow_line", "FollowLine"),
        takes_follow_target_params=False,
    ),
    "corridor_follow": Top(
        "corridor_follow",
        "CorridorFollow: a LIDAR's nearest return per revolution keeps it clear of the walls",
        camera=False,
        tables={
            "corridor": ("fpga_robotics.hw.lidar_params", "CorridorParams"),
            "nearest": ("fpga_robotics.hw.lidar_params", "NearestParams"),
        },
        component=("fpga_robotics.hw.corridor_follow", "CorridorFollow"),
        takes_follow_target_params=False,
    ),
    "corridor_follow_uart": Top(
        "corridor_follow_uart",
        "CorridorFollow on the LIDAR's serial protocol: a UART and a packet decoder before it",
        camera=False,
        tables={
            "corridor": ("fpga_robotics.hw.lidar_params", "CorridorParams"),
            "nearest": ("fpga_robotics.hw.lidar_params", "NearestParams"),
            "uart": ("fpga_robotics.hw.lidar_params", "UartParams"),
        },
        component=("fpga_robotics.hw.corridor_follow_uart", "CorridorFollowUart"),
        takes_follow_target_params=False,
    ),
    "turret_tracker": Top(
        "turret_tracker",
        "TurretTracker: FollowTarget, and a pan camera on a servo that keeps a second target centred",
        camera=True,
        tables={"turret": ("fpga_robotics.hw.turret_params", "TurretParams")},
        component=("fpga_robotics.hw.turret_tracker", "TurretTracker"),
        bindings={"servo": {"angle": "servo_angle"}},
        frame_channels={"turret_pixels": ("fpga_robotics.sim.models.turret", "TurretChannel")},
    ),
}


def register_top(top):
    """Make ``top`` (a ``Top``) available as ``design.top = top.name`` in scenarios."""
    if not isinstance(top, Top):
        raise TypeError(f"register_top takes a Top, not {top!r}")
    TOPS[top.name] = top
    return top


def get_top(name):
    try:
        return TOPS[name]
    except KeyError:
        raise ValueError(
            f"design.top must be one of {', '.join(map(repr, TOPS))}, got {name!r}"
        ) from None


def foreign_top(port_map):
    """The ``Top`` of a foreign Verilog design (docs/foreign.md) from its ``PortMap``: a
    camera iff the map has a pixel stream, the wheels on the wrapper's ``motor_left``/
    ``motor_right`` (the map's ``outputs``), each ``[connectors.<kind>]`` table as it binds.
    Not registered: built from the scenario's map each time."""
    wheels = all(k in port_map.outputs for k in _WHEELS["wheels"])
    bindings = {
        **(_WHEELS if wheels else {}),
        **{kind: dict(pins) for kind, pins in port_map.connectors.items()},
    }
    if port_map.has_pixels:
        bindings.update(_CAMERA)
    return Top(
        f"verilog:{port_map.top}",
        f"the Verilog design {port_map.top} (port map)",
        camera=port_map.has_pixels,
        bindings=bindings,
        extra_outputs=dict(port_map.extra_outputs),
        component=None,
        takes_follow_target_params=False,
    )


def connector_kinds():
    """Every registered connector kind with pins bound by a port map's ``[connectors]``:
    kind -> {pin: (direction, at most this many bits)} (``port_map.check_connectors``)."""
    return {
        kind: {pin: (spec.direction, spec.width) for pin, spec in cls.pins.items()}
        for kind, cls in CONNECTORS.items()
        if kind not in ("camera", "wheels")
    }


def _load(where):
    if callable(where):
        return where
    module, name = where
    return getattr(importlib.import_module(module), name)


def table_fields(key):
    """The parameter names of design sub-table ``key`` (any top's)."""
    cls = table_class(key)
    return () if cls is None else tuple(f.name for f in dataclasses.fields(cls) if f.init)


def table_class(key):
    """The parameters class of design sub-table ``key`` (any top's), or None."""
    for top in TOPS.values():
        if key in top.tables:
            return _load(top.tables[key])
    return None


def design_tables(top, tables, variant=None):
    """The params objects of ``top``'s sub-tables from ``{key: {field: value}}`` (missing
    tables: the defaults), the buggy ``variant`` (``hw.variants``) applied on top. Raises
    ``ValueError`` naming ``design.<key>.<field>`` or the variant."""
    out = {}
    for key, where in top.tables.items():
        cls = _load(where)
        values = dict(tables.get(key) or {})
        known = {f.name: f for f in dataclasses.fields(cls) if f.init}
        for name, value in values.items():
            if name not in known:
                raise ValueError(
                    f"unknown key design.{key}.{name}; known: {', '.join(sorted(known))}"
                )
            if isinstance(value, list):
                values[name] = tuple(value)
        try:
            out[key] = cls(**values)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"design.{key}: {exc}") from None
    if variant is not None:
        out = _with_variant(top, out, variant)
    return out


def _with_variant(top, tables, name):
    names = [n for n, v in VARIANTS.items() if v.design == top.name]
    if name not in names:
        raise ValueError(
            f"design.variant must be one of {', '.join(map(repr, names))} for "
            f"design.top = {top.name!r}, got {name!r}"
            if names
            else f"design.top = {top.name!r} has no variants (design.variant)"
        )
    params_type = VARIANTS[name].params_type
    key = next(k for k, v in tables.items() if isinstance(v, params_type))
    try:
        return {**tables, key: variant_params(name, tables[key])}
    except ValueError as exc:
        raise ValueError(f"design.variant {name!r}: {exc}") from None


def build_component(top, ft_params, table_params):
    """The Amaranth component of ``top`` (``table_params`` from ``design_tables``)."""
    cls = _load(top.component)
    args = [table_params[k] for k in top.tables]
    if top.takes_follow_target_params:
        args.insert(0, ft_params)
    return cls(*args)
