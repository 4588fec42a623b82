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

All draws come from one generator seeded by the world's seed and a tag of its own, so the
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
        self.noise = [0.0, 0.0]
        self.slip_until = -math.inf
        self._events = []

    def step(self, h, left, right, t):
        """Wheel speeds ``left, right`` (rad/s) as the wheels really turn during the step of
        ``h`` s starting at ``t``, and the traction factor then: ``(left, right, traction)``."""
        if self.sigma > 0.0:
            a = math.exp(-h / NOISE_TAU)
            b = self.sigma * math.sqrt(1.0 - a * a)
            z = self.rng.standard_normal(2)
            self.noise = [a * self.noise[0] + b * z[0], a * self.noise[1] + b * z[1]]
        c = self.config
        if c.slip_rate_hz > 0.0 and t >= self.slip_until:
            if self.rng.random() < -math.expm1(-c.slip_rate_hz * h):
                self.slip_until = t + c.slip_duration_s
                self._events.append(f"wheel slip: traction x{c.slip_traction:g} for "
                                    f"{c.slip_duration_s:g} s")
        traction = c.slip_traction if t < self.slip_until else 1.0
        return (left * self.gains[0] + self.noise[0], right * self.gains[1] + self.noise[1],
                traction)

    def drain_events(self):
        events, self._events = self._events, []
        return events
