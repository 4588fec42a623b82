"""A scenario's ``[[robot.sensors]]`` and ``[[robot.actuators]]`` tables, validated into
``ConnectorSpec``s (docs/connectors.md).

Each table has ``kind`` (a registered connector kind), an optional ``name`` (default: the
kind, numbered when a kind appears twice), the mount keys ``forward``, ``left``, ``height``
(m) and ``yaw_deg`` (degrees, left positive), an optional ``ports = {pin = "design_port"}`` overriding the design's
binding, and the kind's own parameters (checked by its ``parse``).
"""

import re
from dataclasses import dataclass, field
from typing import Annotated

from pydantic import BeforeValidator, ConfigDict, Field

from fpga_robotics.loop.connectors import CONNECTORS, ConnectorError
from fpga_robotics.loop.connectors.base import Mount, parse_mount
from fpga_robotics.sim.world.schema import KeyModel, fail, validate

__all__ = ["ConnectorSpec", "ConnectorTableKeys", "parse_connectors"]

_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,31}")


#: The wheels are always there, bound by the design (its motor_left and motor_right): no table
#: declares them.
_NOT_DECLARED = ("wheels",)


def _kinds():
    return ", ".join(sorted(k for k in CONNECTORS if k not in _NOT_DECLARED))


def _kind(value):
    if value in _NOT_DECLARED:
        fail(
            "the wheels are always there, bound in the design (its motor_left and "
            "motor_right outputs, or its connectors attribute); leave this table out",
            sub=":",
        )
    if not isinstance(value, str) or value not in CONNECTORS:
        fail(f"unknown connector kind {value!r}; choose one of: {_kinds()}", sub=":")
    return value


def _name(value):
    if not (isinstance(value, str) and _NAME.fullmatch(value)):
        fail(f"must be a word of letters, digits and _ (at most 32), got {value!r}")
    return value


def _ports(value):
    if not (isinstance(value, dict) and all(isinstance(p, str) and p for p in value.values())):
        fail(f'must be a table pin = "design_port", got {value!r}')
    return dict(value)


class ConnectorTableKeys(KeyModel):
    """The keys every ``[[robot.sensors]]`` / ``[[robot.actuators]]`` table has; the mount's
    are ``MountKeys``, the rest the kind's own ``keys`` (``loop.connectors.base``)."""

    model_config = ConfigDict(extra="allow", frozen=True)

    kind: Annotated[str, BeforeValidator(_kind), Field(description="a registered kind")]
    name: Annotated[str, BeforeValidator(_name)] = None  # None: the kind, numbered
    ports: Annotated[dict, BeforeValidator(_ports)] = Field(default_factory=dict)

    @classmethod
    def missing_key(cls, path, key, doc):
        return f'{path.rpartition(".")[0]} needs kind = "...", one of: {_kinds()}'


@dataclass(frozen=True)
class ConnectorSpec:
    kind: str
    name: str
    role: str  # "sensor" or "actuator": the list it was declared in
    mount: Mount
    params: object
    ports: dict = field(default_factory=dict)  # pin -> design port (overrides the design's)
    where: str = ""  # the table, for messages: "robot.sensors[0]"


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
            common = validate(ConnectorTableKeys, table, where, ConnectorError)
            kind, ports = common.kind, common.ports
            table = dict(common.model_extra)  # the mount's keys and the kind's own
            cls = CONNECTORS[kind]
            if cls.role != role:
                article = "an" if cls.role == "actuator" else "a"
                raise ConnectorError(
                    f"{where}: a {kind!r} connector is {article} {cls.role}; "
                    f"declare it in [[robot.{cls.role}s]]"
                )
            name = common.name
            if name is None:
                name = kind if kind not in names else f"{kind}{i}"
            if name in names:
                raise ConnectorError(f"{where}.name {name!r} is used twice")
            names.add(name)
            mount, table = parse_mount(table, where)
            for pin in ports:
                if pin not in cls.pins:
                    raise ConnectorError(
                        f"{where}.ports: a {kind!r} connector has no pin "
                        f"{pin!r}; its pins: {', '.join(cls.pins)}"
                    )
            params = cls.parse(table, where)
            specs.append(ConnectorSpec(kind, name, role, mount, params, dict(ports), where))
    return tuple(specs)
