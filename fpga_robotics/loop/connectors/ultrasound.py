"""UltrasoundConnector (``kind = "ultrasound"``): an HC-SR04 on the robot, at pin level.

The design drives ``trig`` (watched) and reads ``echo``. When TRIG falls, the connector
measures the range from the sensor's mount into the world (``sim.ultrasound.range_to``, the
world as it is at that physics step), asks the module for its answer
(``HCSR04Module.on_trigger``) and schedules ECHO's rise and fall on their exact edges. A
trigger the module ignores (too short, or while it is busy) schedules nothing.
"""

import math
from typing import ClassVar

from fpga_robotics.loop.connectors.base import (
    Connector,
    ConnectorError,
    Pin,
    check_numbers,
    refuse_above_ceiling,
    refuse_unknown_keys,
    register,
)
from fpga_robotics.sim.world.ultrasound import HCSR04Module, HCSR04Params, range_to

__all__ = ["UltrasoundConnector"]

#: key -> (lower bound, upper bound, unit, lower bound excluded) of the scenario table.
_KEYS = {
    "cone_deg": (0.0, 60.0, "degrees", True),
    "min_range": (0.0, 1.0, "m", False),
    "max_range": (0.0, 10.0, "m", True),
    "temperature_c": (-40.0, 85.0, "degrees C", False),
    "noise_std": (0.0, 0.1, "m", False),
    "timeout_s": (0.0, 0.2, "s", True),
    "echo_delay_s": (0.0, 0.01, "s", False),
    "min_trigger_s": (0.0, 0.001, "s", False),
}


@register
class UltrasoundConnector(Connector):
    """An HC-SR04: ``trig`` out of the design (1 bit), ``echo`` into it (1 bit)."""

    kind = "ultrasound"
    pins: ClassVar[dict] = {"trig": Pin("out"), "echo": Pin("in")}
    watch = ("trig",)

    def __init__(self, name, mount, params, *, world, rng):
        super().__init__(name, mount, params, world=world, rng=rng)
        self.module = HCSR04Module(params, rng)
        self._rise = None  # TRIG's last rising edge
        #: Triggers the module ignored (too short, or during a measurement).
        self.ignored = 0
        self._last = None  # (echo width in edges, true range or None, clock_hz)
        self._echo = None  # (ECHO's fall edge, its _last): the echo scheduled, not yet over

    @classmethod
    def parse(cls, table, where):
        defaults = HCSR04Params()
        refuse_unknown_keys(table, _KEYS, where, cls.kind)
        values = check_numbers(table, _KEYS, defaults, where)
        if not values["min_range"] < values["max_range"]:
            raise ConnectorError(
                f"{where}.max_range must be greater than min_range "
                f"({values['min_range']:g} m), got {values['max_range']:g}"
            )
        return HCSR04Params(**values)

    @classmethod
    def check_run(cls, params, mount, where, sim, room):
        refuse_above_ceiling(mount, where, room)

    def start(self, io):
        self._rise, self._last, self._echo = None, None, None
        self.module.busy_until = -1

    def sensor_pose(self):
        """``(x, y, heading)`` of the sensor in the world now."""
        return self.mount.world_pose(*self.world.robot_pose())

    def on_change(self, io, pin, value, t):
        if pin != "trig":
            return
        self._echo_over(io.cycle)
        if value:
            self._rise = io.cycle
            return
        if self._rise is None:  # a fall without a rise seen (high since the reset)
            return
        rise, fall, self._rise = self._rise, io.cycle, None
        x, y, heading = self.sensor_pose()
        distance = range_to(self.world, x, y, heading, self.mount.height, self.params)
        echo = self.module.on_trigger(rise, fall, distance, io.clock_hz)
        if echo is None:
            self.ignored += 1
            return
        io.schedule(echo[0], "echo", 1)
        io.schedule(echo[1], "echo", 0)
        self._echo = (echo[1], (echo[1] - echo[0], distance, io.clock_hz))

    def after_step(self, io, t):
        self._echo_over(io.cycle)

    def _echo_over(self, cycle):
        """The scheduled echo is the last one once ECHO has fallen (by edge ``cycle``): a row
        shows no echo the design has not had yet."""
        if self._echo is not None and self._echo[0] <= cycle:
            self._last, self._echo = self._echo[1], None

    def measurement(self):
        """The last ECHO that has fallen: its width in edges (``echo_edges``), the distance it
        encodes (``echo_m``, half the round trip at the module's speed of sound), the true
        range when TRIG fell (``range_m``, NaN when nothing was in range) and ``timeout`` (1
        when the module gave its time-out pulse); empty before the first echo."""
        if self._last is None:
            return {}
        width, distance, clock_hz = self._last
        return {
            "echo_edges": float(width),
            "echo_m": width / clock_hz * self.params.speed_of_sound / 2.0,
            "range_m": math.nan if distance is None else float(distance),
            "timeout": float(distance is None),
        }

    def map_overlay(self):
        """The sensor, and a ray along its axis as long as the last echo says (none after a
        time-out)."""
        x, y, heading = self.sensor_pose()
        out = {"points": ((x, y),), "states": (1,)}
        m = self.measurement()
        if m and not m["timeout"]:
            reach = m["echo_m"]
            out["rays"] = (
                ((x, y), (x + reach * math.cos(heading), y + reach * math.sin(heading))),
            )
        return out
