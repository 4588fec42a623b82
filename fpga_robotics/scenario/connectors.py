"""A scenario's ``[[robot.sensors]]`` and ``[[robot.actuators]]`` tables, validated into
``ConnectorSpec``s (docs/connectors.md).

Each table has ``kind`` (a registered connector kind), an optional ``name`` (default: the
kind, numbered when a kind appears twice), the mount keys ``forward``, ``left``, ``height``
(m) and ``yaw_deg`` (degrees, left positive), an optional ``ports = {pin = "design_port"}`` overriding the design's
binding, and the kind's own parameters (checked by its ``parse``).
"""

import re
from dataclasses import dataclass, field

from fpga_robotics.loop.connectors import CONNECTORS, ConnectorError
from fpga_robotics.loop.connectors.base import Mount, parse_mount

__all__ = ["ConnectorSpec", "parse_connectors"]

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,31}")


@dataclass(frozen=True)
class ConnectorSpec:
    kind: str
    name: str
    role: str  # "sensor" or "actuator": the list it was declared in
    mount: Mount
    params: object
    ports: dict = field(default_factory=dict)  # pin -> design port (overrides the design's)


def parse_connectors(robot):
    """``robot.sensors`` and ``robot.actuators`` of the scenario's ``robot`` table (which
    are removed from it) as a tuple of ``ConnectorSpec``. Raises ``ConnectorError``."""
    specs, names = [], set()
    for role, key in (("sensor", "sensors"), ("actuator", "actuators")):
        tables = robot.pop(key, [])
        if not isinstance(tables, list):
            raise ConnectorError(
                f"robot.{key} must be an array of tables ([[robot.{key}]] in "
                f"a file), got {tables!r}"
            )
        for i, table in enumerate(tables):
            where = f"robot.{key}[{i}]"
            if not isinstance(table, dict):
                raise ConnectorError(f"{where} must be a table, got {table!r}")
            table = dict(table)
            kind = table.pop("kind", None)
            if kind is None:
                raise ConnectorError(
                    f'{where} needs kind = "...", one of: {", ".join(sorted(CONNECTORS))}'
                )
            if not isinstance(kind, str) or kind not in CONNECTORS:
                raise ConnectorError(
                    f"{where}.kind: unknown connector kind {kind!r}; choose "
                    f"one of: {', '.join(sorted(CONNECTORS))}"
                )
            cls = CONNECTORS[kind]
            if cls.role != role:
                raise ConnectorError(
                    f"{where}: a {kind!r} connector is an {cls.role}; "
                    f"declare it in [[robot.{cls.role}s]]"
                )
            name = table.pop("name", None)
            if name is None:
                name = kind if kind not in names else f"{kind}{i}"
            if not (isinstance(name, str) and _NAME.fullmatch(name)):
                raise ConnectorError(
                    f"{where}.name must be a word of letters, digits and _ "
                    f"(at most 32), got {name!r}"
                )
            if name in names:
                raise ConnectorError(f"{where}.name {name!r} is used twice")
            names.add(name)
            mount, table = parse_mount(table, where)
            ports = table.pop("ports", {})
            if not (
                isinstance(ports, dict) and all(isinstance(p, str) and p for p in ports.values())
            ):
                raise ConnectorError(
                    f'{where}.ports must be a table pin = "design_port", got {ports!r}'
                )
            for pin in ports:
                if pin not in cls.pins:
                    raise ConnectorError(
                        f"{where}.ports: a {kind!r} connector has no pin "
                        f"{pin!r}; its pins: {', '.join(cls.pins)}"
                    )
            params = cls.parse(table, where)
            specs.append(ConnectorSpec(kind, name, role, mount, params, dict(ports)))
    return tuple(specs)
