"""``FollowLine``: one to three KY-033 line sensors to wheel speeds (DPS)."""

from amaranth import Cat, Const, Module, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .motor import DPS_BITS
from .sensor_params import FollowLineParams
from .validate import CheckedArguments

__all__ = ["FollowLine", "FollowLineParams", "line_command"]

# The KY-033 (TCRT5000 reflective sensor and an LM393 comparator) drives its digital output
# high over a dark line, where no infrared comes back: "Line tracker is over a line ...
# Sensor Signal: Digital On" (Joy-IT sensor kit, https://sensorkit.joy-it.net/en/sensors/ky-033),
# and for the TCRT5000 tracker modules in general "infrared rays ... not being reflected back
# ... the output modules is high" (https://hdelectronicseg.com/products/line-tracker-sensor).
# Hence ``active_high`` by default.

LEFT, RIGHT = 0, 1


def line_command(params, bits, side):
    """``(left, right, side)``: the wheel command (DPS) and the new last-seen side (0 left,
    1 right) for the synchronised bits ``bits`` (bit i = sensor i from the left; 1 = line)
    and the last-seen side ``side``. The control law of ``FollowLine``'s docstring."""
    p = params
    n = p.n_sensors
    seen = [(bits >> i) & 1 for i in range(n)]

    def turn(towards, amount):
        if towards == LEFT:
            return p.base_dps - amount, p.base_dps + amount
        return p.base_dps + amount, p.base_dps - amount

    straight = (p.base_dps, p.base_dps)
    if n == 1:
        on_line = seen[0]
        # Over the line: move off it, away from the line's body; off it: back towards it.
        edge = LEFT if p.edge_side == "left" else RIGHT
        towards = edge if on_line else 1 - edge
        return (*turn(towards, p.gentle_turn_dps), side)
    left, right = seen[0], seen[-1]
    if left and not right:
        side = LEFT
    elif right and not left:
        side = RIGHT
    if n == 2:  # straddling the line: a sensor that touches it steers back over it
        if left != right:
            return (*turn(LEFT if left else RIGHT, p.sharp_turn_dps), side)
        return (*straight, side)
    centre = seen[1]
    if left == right:
        if left or centre:  # 111, 101, 010
            return (*straight, side)
        # 000: lost; turn in place towards the side where the line was last seen.
        if side == LEFT:
            return -p.search_dps, p.search_dps, side
        return p.search_dps, -p.search_dps, side
    amount = p.gentle_turn_dps if centre else p.sharp_turn_dps
    return (*turn(LEFT if left else RIGHT, amount), side)


class FollowLine(CheckedArguments, wiring.Component):
    """Line follower (Verilog module ``follow_line``).

    **Synchroniser.** Each bit of ``line`` passes two flops (inverted first when
    ``active_high`` is False): a bit sampled at edge ``e`` shows on ``line_seen`` after edge
    ``e + 1``; ``line_seen`` bit i is 1 when sensor i is over the line.

    **Control law.** At every edge the command register loads the command of ``line_seen``
    and the last-seen side (so a change of ``line`` sampled at edge ``e`` moves the wheels
    after edge ``e + 2``). With ``B = base_dps``, ``G = gentle_turn_dps``,
    ``S = sharp_turn_dps``, ``Q = search_dps``, a turn to the left is ``(B - x, B + x)``
    (``left, right``), to the right ``(B + x, B - x)``:

    - 3 sensors (left, centre, right): centre only, all three, or both sides without the
      centre: straight ``(B, B)``; left only: sharp left (``x = S``); left and centre: gentle
      left (``x = G``); mirrored for the right; none: search, turning in place towards the
      side where the line was last seen (``(-Q, Q)`` for the left, ``(Q, -Q)`` for the right).
    - 2 sensors, straddling the line: none or both: straight; left only: sharp left; right
      only: sharp right.
    - 1 sensor on an edge of the line (``edge_side``; "left": the line lies to the sensor's
      right): over the line, a gentle turn towards the edge side; off it, a gentle turn the
      other way.

    The last-seen side becomes left when the leftmost sensor sees the line and the rightmost
    does not, right in the mirrored case, and otherwise keeps its value (it only steers the
    3-sensor search).

    **Reset.** ``motor_left = motor_right = 0``, ``line_seen = 0``, last-seen side left; the
    first command loads at edge 1.

    Parameters
    ----------
    params : FollowLineParams, optional

    Members
    -------
    line : ``In(n_sensors)``
        The sensors' digital outputs (asynchronous), bit i = sensor i from the robot's left.
    motor_left, motor_right : ``Out(signed(16))``
        Wheel speeds (DPS), registered.
    line_seen : ``Out(n_sensors)``
        The synchronised bits the controller acts on (1 = line under the sensor).
    """

    @staticmethod
    def check_arguments(params=None):
        if params is not None and not isinstance(params, FollowLineParams):
            raise TypeError(f"params must be a FollowLineParams, not {params!r}")

    def __init__(self, params=None):
        self.params = params = FollowLineParams() if params is None else params
        n = params.n_sensors
        super().__init__(
            {
                "line": In(n),
                "motor_left": Out(signed(DPS_BITS)),
                "motor_right": Out(signed(DPS_BITS)),
                "line_seen": Out(n),
            }
        )

    def elaborate(self, platform):
        m = Module()
        p = self.params
        n = p.n_sensors

        line_in = self.line if p.active_high else ~self.line
        sync1 = Signal(n)
        m.d.sync += [sync1.eq(line_in), self.line_seen.eq(sync1)]

        # The whole command in one register, loaded whole from a table of every case.
        state = Signal(
            data.StructLayout(
                {
                    "left": signed(DPS_BITS),
                    "right": signed(DPS_BITS),
                    "side": 1,
                }
            )
        )
        m.d.comb += [self.motor_left.eq(state.left), self.motor_right.eq(state.right)]
        with m.Switch(Cat(self.line_seen, state.side)):
            for index in range(1 << (n + 1)):
                bits, side = index & ((1 << n) - 1), index >> n
                left, right, new_side = line_command(p, bits, side)
                with m.Case(index):
                    m.d.sync += state.eq(
                        Cat(
                            Const(left, signed(DPS_BITS)),
                            Const(right, signed(DPS_BITS)),
                            Const(new_side, 1),
                        )
                    )
        return m
