"""MotorConnector: design to world. The design's wheel commands reach the simulated motors
after a delay.

On the robot, a frame's DPS command leaves the FPGA over SPI some time after the frame was
captured (exposure, readout, processing, the bus). Here each command is scheduled on the
physics step at which it takes effect and applied with ``world.set_wheel_dps`` when the
simulation reaches that step; until then the previous command stays in force.
"""

from collections import deque
from typing import ClassVar

from fpga_robotics.loop.connectors.base import Connector, Pin, register
from fpga_robotics.loop.connectors.sampling import StepSampling

__all__ = ["MotorConnector"]


@register
class MotorConnector(StepSampling, Connector):
    """Delayed delivery of wheel commands (DPS) to the world: the connector of kind
    ``wheels``, bound to the design's ``motor_left`` and ``motor_right`` outputs.

    In frame timing the closed loop schedules each frame's command itself. In real-clock
    timing a change at edge ``e`` takes effect at the first physics step at or after
    ``e / clock_hz + delay`` (``configure_real_clock``), the last change that falls on a
    step winning: the pins are sampled once a step (``connectors.sampling``, ``sample``).

    Parameters
    ----------
    world : World
        Receives ``set_wheel_dps(left, right)``.
    """

    kind = "wheels"
    role = "actuator"
    pins: ClassVar[dict] = {
        "motor_left": Pin("out", 16, signed=True),
        "motor_right": Pin("out", 16, signed=True),
    }
    watch = ()  # sampled instead (sample_edge_after)

    def __init__(self, world):
        self.name, self.mount, self.params, self.world = "wheels", None, None, world
        self._pending = deque()  # (step, left, right), in step order
        self.applied = (0, 0)
        self.sampled = None  # real-clock timing: the pins' values at the last sample

    def configure_real_clock(self, dt, delay):
        """Real-clock timing: physics steps of ``dt`` s, commands acting ``delay`` s after the
        pins change."""
        self.configure(dt, delay)

    def sample(self, io):
        """Real-clock timing: read the pins at edge ``io.cycle`` (out of reset, or a
        ``sample_edge_after`` edge); a new pair of values acts after the delay."""
        value = (io.peek("motor_left"), io.peek("motor_right"))
        if value != self.sampled:
            self.sampled = value
            step = self.step_of(io, io.cycle)
            if self._pending and step < self._pending[-1][0]:
                step = self._pending[-1][0]
            self.schedule(step, *value)

    def schedule(self, step, left_dps, right_dps):
        """Apply ``(left_dps, right_dps)`` at physics step ``step`` (not before)."""
        if self._pending and step < self._pending[-1][0]:
            raise ValueError("motor commands must be scheduled in time order")
        self._pending.append((step, int(left_dps), int(right_dps)))

    def apply_due(self, step):
        """Send every command due at or before ``step`` to the world (the last one wins)."""
        due = None
        while self._pending and self._pending[0][0] <= step:
            due = self._pending.popleft()
        if due is not None and (due[1], due[2]) != self.applied:
            self.world.set_wheel_dps(due[1], due[2])
            self.applied = (due[1], due[2])
        return due is not None
