"""Seeded imperfections of the robot's drive: per-wheel gain error, speed noise, slips.

- **Gain error** (``robot.motor_gain_error = e``): each wheel turns at ``1 + U(-e, e)`` times
  its commanded speed, drawn once per run (a robot that pulls to one side).
- **Speed noise** (``robot.motor_noise_dps = s``): each wheel's speed carries a random error
  with standard deviation ``s`` deg/s and a correlation time of ``NOISE_TAU`` (an
  Ornstein-Uhlenbeck process, sampled exactly at every physics step, so its statistics do
  not depend on the step).
- **Slips** (``robot.slip_rate_hz``, ``slip_duration_s``, ``slip_traction``): slip events
  start as a Poisson process; during one the wheels' traction is ``slip_traction`` times
  its value (an event ``wheel slip`` is logged).

All draws come from one generator (normals and uniforms drawn in blocks) seeded by the world's seed and a tag of its own, so the
people's randomness does not change, and the ideal robot (all zero) draws nothing.
"""

import math

import numpy as np

from .kinematics import DEG

__all__ = ["NOISE_TAU", "MotorUncertainty"]

#: Correlation time of the wheel speed noise, s.
NOISE_TAU = 0.1
_STREAM = 0x0DD5  # the generator's tag next to the world's seed


class MotorUncertainty:
    """The drive's imperfections for one run (``config.Uncertainty``, the world's seed)."""

    def __init__(self, config, seed):
        self.config = config
        self.rng = np.random.default_rng(np.random.SeedSequence([int(seed), _STREAM]))
        e = config.motor_gain_error
        self.gains = tuple(1.0 + self.rng.uniform(-e, e, 2)) if e > 0 else (1.0, 1.0)
        self.sigma = config.motor_noise_dps * DEG  # rad/s
        self.noise_left = self.noise_right = 0.0  # rad/s
        self.slip_until = -math.inf
        self.events = []  # "wheel slip: ..." since the last drain_events()
        # Draws come in blocks (one generator call per block, not per step): the same
        # numbers in the same order as one at a time would give for each kind of draw.
        self._normals, self._uniforms = [], []
        self._n = self._u = 0
        self._step_h = None  # the step the OU coefficients are for

    _BLOCK = 4096

    def _uniform(self):
        if self._u >= len(self._uniforms):
            self._uniforms, self._u = self.rng.random(self._BLOCK).tolist(), 0
        self._u += 1
        return self._uniforms[self._u - 1]

    def step(self, h, left, right, t):
        """Wheel speeds ``left, right`` (rad/s) as the wheels really turn during the step of
        ``h`` s starting at ``t``, and the traction factor then: ``(left, right, traction)``."""
        c = self.config
        if h != self._step_h:
            self._step_h = h
            self._a = math.exp(-h / NOISE_TAU)
            self._b = self.sigma * math.sqrt(1.0 - self._a * self._a)
            self._p_slip = -math.expm1(-c.slip_rate_hz * h)
        gl, gr = self.gains
        if self.sigma > 0.0:
            i = self._n
            if i + 2 > len(self._normals):
                self._normals, i = self.rng.standard_normal(2 * self._BLOCK).tolist(), 0
            self._n = i + 2
            a, b = self._a, self._b
            nl = self.noise_left = a * self.noise_left + b * self._normals[i]
            nr = self.noise_right = a * self.noise_right + b * self._normals[i + 1]
            left, right = left * gl + nl, right * gr + nr
        else:
            left, right = left * gl, right * gr
        if c.slip_rate_hz > 0.0 and t >= self.slip_until and self._uniform() < self._p_slip:
            self.slip_until = t + c.slip_duration_s
            self.events.append(
                f"wheel slip: traction x{c.slip_traction:g} for {c.slip_duration_s:g} s"
            )
        return left, right, (c.slip_traction if t < self.slip_until else 1.0)

    def drain_events(self):
        events, self.events = self.events, []
        return events
