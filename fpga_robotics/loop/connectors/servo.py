"""ServoConnector: design to world. The GoPiGo3's servo port turns a pan servo and whatever is
mounted on it (a camera with ``on = "<servo name>"``).

The design's 10-bit signed ``angle`` (``+-500`` for ``+-90`` degrees: the pulse offset from
1500 µs, sim/world/servo.py) reaches the servo as the wheel commands do, over the same SPI
path: ``sim.actuation_delay`` after the design gives it (compressed timing: after the capture
of the frame it answers). The horn then turns at the part's speed (``speed_deg_s``) to the
commanded angle. The mount is where the horn's axis stands on the robot; ``yaw_deg`` is the
direction its zero points to (left of the heading positive).
"""

import math
from collections import deque
from typing import ClassVar

from fpga_robotics.loop.connectors.base import Connector, Pin, check_number, register
from fpga_robotics.loop.connectors.sampling import StepSampling
from fpga_robotics.sim.world.servo import SERVO_RANGE_DEG, SERVO_SPEED_DEG_S, ServoModel

__all__ = ["ServoConnector", "ServoParams"]


class ServoParams:
    """A servo table's keys: ``speed_deg_s`` (no-load speed) and ``range_deg`` (the angle
    of a full command, 500)."""

    __slots__ = ("range_deg", "speed_deg_s")

    def __init__(self, speed_deg_s=SERVO_SPEED_DEG_S, range_deg=SERVO_RANGE_DEG):
        self.speed_deg_s, self.range_deg = speed_deg_s, range_deg

    def __eq__(self, other):
        return isinstance(other, ServoParams) and (self.speed_deg_s, self.range_deg) == (
            other.speed_deg_s,
            other.range_deg,
        )

    def __repr__(self):
        return f"ServoParams(speed_deg_s={self.speed_deg_s}, range_deg={self.range_deg})"


@register
class ServoConnector(StepSampling, Connector):
    """A pan servo on the robot, driven by the design's ``angle`` output (in real-clock
    timing sampled once a physics step: ``connectors.sampling``, ``sample``)."""

    kind = "servo"
    role = "actuator"
    pins: ClassVar[dict] = {"angle": Pin("out", 10, signed=True)}
    watch = ()  # sampled instead
    #: Runs in compressed timing: each frame's command acts after the actuation delay.
    frame_level = True

    def __init__(self, name, mount, params, *, world=None, rng=None):
        super().__init__(name, mount, params, world=world, rng=rng)
        self.model = ServoModel(speed=math.radians(params.speed_deg_s), range_deg=params.range_deg)
        self._pending = deque()  # (physics step, command), in step order
        self.commanded = 0
        self.sampled = 0  # real-clock timing: the pin at the last sample (0: the horn's rest)

    @classmethod
    def parse(cls, table, where):
        params = ServoParams(
            speed_deg_s=check_number(
                table,
                "speed_deg_s",
                SERVO_SPEED_DEG_S,
                where,
                lo=0,
                hi=10000,
                unit="deg/s",
                lo_open=True,
            ),
            range_deg=check_number(
                table, "range_deg", SERVO_RANGE_DEG, where, lo=1, hi=180, unit="deg"
            ),
        )
        super().parse(
            {k: v for k, v in table.items() if k not in ("speed_deg_s", "range_deg")}, where
        )
        return params

    def schedule(self, step, command):
        """The command ``command`` acts at physics step ``step`` (not before)."""
        if self._pending and step < self._pending[-1][0]:
            step = self._pending[-1][0]
        self._pending.append((step, int(command)))

    def sample(self, io):
        """Real-clock timing: read the angle pin at edge ``io.cycle``; a new value acts
        after the delay."""
        value = io.peek("angle")
        if value != self.sampled:
            self.sampled = value
            self.schedule(self.step_of(io, io.cycle), value)

    def apply_due(self, step):
        while self._pending and self._pending[0][0] <= step:
            self.commanded = self._pending.popleft()[1]
            self.model.command(self.commanded)

    def step(self, dt):
        """The horn turns for one physics step."""
        self.model.step(dt)

    @property
    def angle(self):
        """The horn's angle now, rad (left positive)."""
        return self.model.angle

    def measurement(self):
        return {"angle_deg": math.degrees(self.model.angle), "command": self.commanded}
