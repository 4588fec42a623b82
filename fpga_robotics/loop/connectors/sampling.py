"""Actuator pins sampled once a physics step (real-clock timing).

A wheel or servo command acts at the first physics step at or after ``delay`` seconds from the
edge its pin changed at, and of the changes acting at one step the last wins. So such a pin
need not be watched (one design stop per change): reading it at the last edge whose change
acts at each step gives the same commands at the same steps, at one stop a step however
often the design changes it. ``StepSampling`` finds those edges.
"""

import math

__all__ = ["StepSampling"]


class StepSampling:
    """Where to sample an actuator's pins: physics steps of ``dt`` s, commands acting
    ``delay`` s after the pins change (``configure``)."""

    dt = delay = None

    def configure(self, dt, delay):
        self.dt, self.delay = dt, delay

    def step_of(self, io, edge):
        """The physics step at which a change of the pins at ``edge`` takes effect."""
        return math.ceil((io.time_of(edge) + self.delay) / self.dt - 1e-9)

    def _last_edge_of(self, io, step):
        """The last edge whose change takes effect at or before ``step`` (-1: none)."""
        edge = max(-1, math.floor((step * self.dt - self.delay) * io.clock_hz))
        while self.step_of(io, edge + 1) <= step:  # the float estimate, made exact
            edge += 1
        while edge >= 0 and self.step_of(io, edge) > step:
            edge -= 1
        return edge

    def sample_edge_after(self, io, edge):
        """The next edge after ``edge`` at which the pins must be read: the last one whose
        change takes effect at its step."""
        step = self.step_of(io, edge)
        while (last := self._last_edge_of(io, step)) <= edge:
            step += 1
        return last
