"""LineSensorsConnector (``kind = "line_sensors"``): one to three KY-033 line sensors under
the robot, on one design input ``line`` (bit i = sensor i, counted from the robot's left).

Each sensor sits at ``forward``/``left`` of the connector's mount (by default the robot's
centre), at the mount's height. Before every physics step the connector reads the floor
under each sensor at the robot's pose at the step's start (``sim.line_sensor.KY033``) and
pokes the bits, which hold for the whole step: a line edge is seen to within one physics
step (the world moves only between steps, so the pose inside a step is not known yet).
"""

import math
from dataclasses import dataclass, replace
from typing import ClassVar

from fpga_robotics.loop.connectors.base import (
    Connector,
    ConnectorError,
    Mount,
    Pin,
    check_number,
    refuse_unknown_keys,
    register,
)
from fpga_robotics.sim.world.line_sensor import KY033, KY033Params

__all__ = ["LineSensorsConnector", "LineSensorsParams"]

MAX_SENSORS = 3

#: key -> (lower bound, upper bound, unit, lower bound excluded) of the module's keys.
_MODULE_KEYS = {
    "threshold": (0.0, 1.0, "", True),
    "noise_std": (0.0, 1.0, "", False),
    "spot_radius": (0.0, 0.02, "m", True),
    "max_height": (0.0, 0.1, "m", True),
}


@dataclass(frozen=True)
class LineSensorsParams:
    sensors: tuple  # ((forward, left), ...), m, ordered from the robot's left to its right
    module: KY033Params


@register
class LineSensorsConnector(Connector):
    """KY-033 line sensors: ``line`` into the design, one bit per sensor."""

    kind = "line_sensors"
    role = "sensor"
    #: The width of ``line`` is the number of sensors (set per connector).
    pins: ClassVar[dict] = {"line": Pin("in", MAX_SENSORS)}

    def __init__(self, name, mount, params, *, world, rng):
        super().__init__(name, mount, params, world=world, rng=rng)
        self.pins = {"line": Pin("in", len(params.sensors))}
        module = params.module
        if mount.height > 0:  # the mount's height is the module's
            module = replace(module, height=mount.height)
        self.module = KY033(module, rng)  # one model reads every sensor (same settings)
        #: Each sensor as a ``Mount`` on the robot: its offset turned by the connector's yaw
        #: and added to the connector's mount (also what the line metrics follow).
        c, s = math.cos(mount.yaw), math.sin(mount.yaw)
        self.sensor_mounts = tuple(
            Mount(
                forward=mount.forward + f * c - left * s,
                left=mount.left + f * s + left * c,
                height=mount.height,
                yaw=mount.yaw,
            )
            for f, left in params.sensors
        )
        self.bits = 0
        self.positions = []

    @classmethod
    def parse(cls, table, where):
        table = dict(table)
        sensors = table.pop("sensors", None)
        refuse_unknown_keys(
            table, _MODULE_KEYS, where, cls.kind, f"sensors, {', '.join(_MODULE_KEYS)}"
        )
        if (
            not isinstance(sensors, list)
            or not 1 <= len(sensors) <= MAX_SENSORS
            or not all(isinstance(s, dict) for s in sensors)
        ):
            raise ConnectorError(
                f"{where}.sensors must be an array of 1 to {MAX_SENSORS} tables "
                f"{{forward = m, left = m}}, ordered from the robot's left to its right, got "
                f"{sensors!r}"
            )
        offsets = []
        for i, s in enumerate(sensors):
            here = f"{where}.sensors[{i}]"
            extra = sorted(k for k in s if k not in ("forward", "left"))
            if extra:
                raise ConnectorError(f"{here}: unknown key {extra[0]!r}; its keys: forward, left")
            offsets.append(
                (
                    check_number(s, "forward", 0.0, here, lo=-1, hi=1, unit="m"),
                    check_number(s, "left", 0.0, here, lo=-1, hi=1, unit="m"),
                )
            )
        for i in range(1, len(offsets)):
            if not offsets[i][1] < offsets[i - 1][1]:
                raise ConnectorError(
                    f"{where}.sensors[{i}].left must be less than sensors[{i - 1}].left "
                    f"({offsets[i - 1][1]:g} m): the sensors are listed from the robot's "
                    f"left (bit 0) to its right, got {offsets[i][1]:g}"
                )
        defaults = KY033Params()
        values = {
            key: check_number(
                table, key, getattr(defaults, key), where, lo=lo, hi=hi, unit=unit, lo_open=open_
            )
            for key, (lo, hi, unit, open_) in _MODULE_KEYS.items()
        }
        return LineSensorsParams(tuple(offsets), replace(defaults, **values))

    def sensor_positions(self):
        """Each sensor's ``(x, y)`` in the world now."""
        pose = self.world.robot_pose()
        return [m.world_pose(*pose)[:2] for m in self.sensor_mounts]

    def read(self):
        """The bits (bit i = sensor i) over the floor under the sensors now."""
        self.positions = self.sensor_positions()
        bits = 0
        for i, bit in enumerate(self.module.outputs(self.world, self.positions)):
            bits |= bit << i
        return bits

    def before_step(self, io, t, dt):
        self.bits = self.read()
        io.poke("line", self.bits)

    def measurement(self):
        """``line`` (the bits as a number) and per sensor i ``line<i>`` (its bit)."""
        out = {"line": float(self.bits)}
        for i in range(len(self.positions)):
            out[f"line{i}"] = float(self.bits >> i & 1)
        return out

    def map_overlay(self):
        """Each sensor where it read the floor, lit when its bit is 1 (over the line)."""
        return {
            "points": tuple((float(x), float(y)) for x, y in self.positions),
            "states": tuple(self.bits >> i & 1 for i in range(len(self.positions))),
        }
