"""A hobby pan servo: a commanded angle reached at the part's slew rate.

The GoPiGo3 drives its two servo ports with a pulse every 20 ms whose width sets the angle
(``set_servo(port, pulse_us)`` in the GoPiGo3 API): 1500 µs centres the horn and a standard
hobby servo turns about 90 degrees either way for 1000..2000 µs. The published turret system
sent the angle as a 10-bit signed number, ``+-500`` for ``+-90`` degrees: the pulse width's
offset from 1500 µs, in µs. Positive turns the horn to the robot's left (counter-clockwise
seen from above, as every angle here).

A servo's own position loop moves the horn towards the command at the motor's speed, which
the datasheets give as the time for 60 degrees without load: 0.1 s/60° for the TowerPro SG90
micro servo at 4.8 V (its datasheet), 0.12-0.2 s/60° for standard-size analogue parts
(e.g. the TowerPro MG995 at 4.8 V: 0.2 s/60°). ``SERVO_SPEED_DEG_S`` takes the SG90's, the
size of the GoPiGo3 kit's servo. The model turns at that speed until it reaches the command
(no overshoot: the part's own controller is well damped at the light load of a camera) and
stops at the mechanical range.
"""

import math
from dataclasses import dataclass

__all__ = [
    "SERVO_COMMAND_FULL",
    "SERVO_RANGE_DEG",
    "SERVO_SPEED_DEG_S",
    "ServoModel",
    "command_to_angle",
]

#: The command of a full quarter turn: ``+-500`` (µs of pulse offset) for ``+-90`` degrees.
SERVO_COMMAND_FULL = 500
#: The angle of ``SERVO_COMMAND_FULL``, degrees.
SERVO_RANGE_DEG = 90.0
#: No-load speed of a TowerPro SG90 at 4.8 V: 60 degrees in 0.1 s (its datasheet).
SERVO_SPEED_DEG_S = 600.0


def command_to_angle(command, range_deg=SERVO_RANGE_DEG):
    """The horn angle (rad) a command asks for: ``command / 500 * range``, clipped to the
    range (a pulse outside 1000..2000 µs drives a real servo against its end stop)."""
    c = max(-SERVO_COMMAND_FULL, min(SERVO_COMMAND_FULL, int(command)))
    return math.radians(c * range_deg / SERVO_COMMAND_FULL)


@dataclass
class ServoModel:
    """The horn's angle (rad, left positive) moving towards ``target`` at ``speed`` rad/s."""

    speed: float = math.radians(SERVO_SPEED_DEG_S)
    range_deg: float = SERVO_RANGE_DEG
    angle: float = 0.0
    target: float = 0.0

    def command(self, command):
        """A new command (the 10-bit signed value the design sends)."""
        self.target = command_to_angle(command, self.range_deg)

    @property
    def rate(self):
        """The horn's angular speed now, rad/s (left positive): full speed until it is there."""
        return (
            0.0
            if self.angle == self.target
            else math.copysign(self.speed, self.target - self.angle)
        )

    def step(self, dt):
        """Move for ``dt`` seconds at most ``speed * dt`` towards the target."""
        error = self.target - self.angle
        reach = self.speed * dt
        self.angle = (
            self.target if abs(error) <= reach else self.angle + math.copysign(reach, error)
        )
        return self.angle
