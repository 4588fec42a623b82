"""MotorConnector: design to world. The design's wheel commands reach the simulated motors
after a delay.

On the robot, a frame's DPS command leaves the FPGA over SPI some time after the frame was
captured (exposure, readout, processing, the bus). Here each command is scheduled on the
physics step at which it takes effect and applied with ``world.set_wheel_dps`` when the
simulation reaches that step; until then the previous command stays in force.
"""

from collections import deque

__all__ = ["MotorConnector"]


class MotorConnector:
    """Delayed delivery of wheel commands (DPS) to the world.

    Parameters
    ----------
    world : World
        Receives ``set_wheel_dps(left, right)``.
    """

    def __init__(self, world):
        self.world = world
        self._pending = deque()  # (step, left, right), in step order
        self.applied = (0, 0)

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
