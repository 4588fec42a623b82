"""Python model of ``FollowLine`` (pure Python, no Amaranth), written from the control law
in docs/sensor_designs.md rather than from the gateware.

``action(params, seen, side)`` names what the robot does for the synchronised bits;
``wheel_command`` turns the action into DPS; ``FollowLineModel`` runs the synchroniser and
the command register edge by edge, so that a test can compare it with the gateware cycle for
cycle.
"""

from dataclasses import dataclass

from fpga_robotics.hw.sensor_params import FollowLineParams

__all__ = ["FollowLineModel", "FollowLineOutputs", "action", "wheel_command"]


def action(params, seen, side):
    """``(action, side)`` for ``seen`` (a tuple of 0/1, sensor 0 the leftmost; 1 = line under
    it) and the last-seen side ("left"/"right"). Actions: "straight", "gentle_left",
    "gentle_right", "sharp_left", "sharp_right", "search_left", "search_right"."""
    seen = tuple(int(bool(b)) for b in seen)
    if len(seen) != params.n_sensors:
        raise ValueError(f"expected {params.n_sensors} bits, got {seen!r}")
    if seen[0] and not seen[-1]:
        side = "left"
    elif seen[-1] and not seen[0]:
        side = "right"
    if params.n_sensors == 1:
        other = "right" if params.edge_side == "left" else "left"
        return f"gentle_{params.edge_side if seen[0] else other}", side
    if params.n_sensors == 2:
        return {
            (0, 0): "straight",
            (1, 1): "straight",
            (1, 0): "sharp_left",
            (0, 1): "sharp_right",
        }[seen], side
    table = {
        (0, 1, 0): "straight",
        (1, 1, 1): "straight",
        (1, 0, 1): "straight",
        (1, 0, 0): "sharp_left",
        (1, 1, 0): "gentle_left",
        (0, 0, 1): "sharp_right",
        (0, 1, 1): "gentle_right",
    }
    return table.get(seen, f"search_{side}"), side


def wheel_command(params, name):
    """``(left, right)`` DPS of an action."""
    b = params.base_dps
    q = params.search_dps
    if name == "straight":
        return b, b
    if name.startswith("search_"):
        return (-q, q) if name.endswith("left") else (q, -q)
    amount = params.gentle_turn_dps if name.startswith("gentle") else params.sharp_turn_dps
    # The wheel on the inside of the turn slows by `amount`, the outer one speeds up by it.
    return (b - amount, b + amount) if name.endswith("left") else (b + amount, b - amount)


@dataclass(frozen=True)
class FollowLineOutputs:
    """The outputs right after one edge."""

    line_seen: int
    motor_left: int
    motor_right: int


class FollowLineModel:
    """``FollowLine`` edge by edge: ``step(line)`` takes the ``line`` value sampled at the next
    edge and returns the outputs right after it."""

    def __init__(self, params=None):
        self.params = FollowLineParams() if params is None else params
        self.reset()

    def reset(self):
        self._flop1 = 0
        self.line_seen = 0
        self.side = "left"
        self.motor = (0, 0)

    def step(self, line):
        n = self.params.n_sensors
        mask = (1 << n) - 1
        bits = [(self.line_seen >> i) & 1 for i in range(n)]
        name, self.side = action(self.params, bits, self.side)
        self.motor = wheel_command(self.params, name)
        # The synchroniser moves on at the same edge.
        self.line_seen = self._flop1
        self._flop1 = (line if self.params.active_high else ~line) & mask
        return FollowLineOutputs(self.line_seen, *self.motor)

    def run(self, lines):
        """Outputs after each edge for the ``line`` values sampled at edges 1, 2, ..."""
        return [self.step(v) for v in lines]
