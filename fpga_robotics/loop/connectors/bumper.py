"""BumperConnector (kind ``bumper``): a contact switch on the robot's front, the smallest
connector of the API and the example of docs/connectors.md.

Its pin ``pressed`` (a design input, 1 bit) is high during a physics step when, at the step's
start, a wall, a piece of furniture or a person is within ``margin`` of the robot's body
inside the bumper's arc (``arc_deg`` wide, centred on the mount's yaw).
"""

import math
from typing import ClassVar

import pymunk

from fpga_robotics.loop.connectors.base import (
    MOUNT_KEYS,
    Connector,
    ConnectorError,
    Pin,
    register,
)

__all__ = ["BumperConnector", "BumperParams"]


class BumperParams:
    """``margin`` (m, how near counts as touching) and ``arc_deg`` (the bumper's width)."""

    def __init__(self, margin=0.005, arc_deg=120.0):
        self.margin, self.arc_deg = float(margin), float(arc_deg)

    def __repr__(self):
        return f"BumperParams(margin={self.margin!r}, arc_deg={self.arc_deg!r})"


@register
class BumperConnector(Connector):
    kind = "bumper"
    pins: ClassVar[dict] = {"pressed": Pin("in", 1)}

    @classmethod
    def parse(cls, table, where):
        limits = {"margin": (0.0, 0.1), "arc_deg": (1.0, 360.0)}
        values = {}
        for key, value in table.items():
            if key not in limits:
                raise ConnectorError(
                    f"{where}: unknown key {key!r} for a bumper; its keys: "
                    f"{', '.join(limits)} (and the mount: {', '.join(MOUNT_KEYS)})"
                )
            lo, hi = limits[key]
            if (
                isinstance(value, bool)
                or not isinstance(value, (int, float))
                or not (lo <= value <= hi)
            ):
                raise ConnectorError(
                    f"{where}.{key} must be a number in {lo:g}..{hi:g}, got {value!r}"
                )
            values[key] = value
        return BumperParams(**values)

    def __init__(self, name, mount, params, *, world, rng):
        super().__init__(name, mount, params, world=world, rng=rng)
        self.pressed = 0

    def touching(self):
        """Whether something is within ``margin`` of the body inside the bumper's arc."""
        world, p = self.world, self.params
        x, y, heading = world.robot_pose()
        reach = world.robot_spec.body_radius + p.margin
        facing = heading + self.mount.yaw
        for hit in world.space.point_query((x, y), reach, pymunk.ShapeFilter()):
            if hit.shape.body is world.robot_body:
                continue
            bearing = math.atan2(hit.point.y - y, hit.point.x - x) - facing
            bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
            if abs(math.degrees(bearing)) <= p.arc_deg / 2:
                return True
        return False

    def before_step(self, io, t, dt):
        pressed = int(self.touching())
        if pressed != self.pressed:
            io.poke("pressed", pressed)
            self.pressed = pressed

    def measurement(self):
        return {"pressed": self.pressed}

    def map_overlay(self):
        x, y, _ = self.mount.world_pose(*self.world.robot_pose())
        return {"points": ((x, y),), "states": (self.pressed,)}
