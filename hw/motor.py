"""Motor controller: per-frame wheel speeds (DPS) from the tracker's results."""

from amaranth import Const, Module, Mux, Signal, signed, unsigned
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .fit import load
from .params import FollowTargetParams

__all__ = ["MotorController"]

#: Width of the motor outputs (signed DPS).
DPS_BITS = 16


def _wrap16(value):
    """A Python int as the 16-bit two's complement value the output register will hold."""
    return ((value + (1 << 15)) & 0xFFFF) - (1 << 15)


class MotorController(wiring.Component):
    """Proportional steering (or the published speed table) with a lost-target search,
    updated once per frame.

    On ``update`` (the tracker's ``frame_done``):

    - found: ``e = centroid_x - width // 2``, ``turn = (kp_num * e) >> kp_shift`` (arithmetic),
      ``left = base_dps[proximity] + turn``, ``right = base_dps[proximity] - turn``, each
      saturated to ``[-max_dps, max_dps]``; the lost count returns to 0 and ``last_side``
      becomes right when ``e >= 0``, else left;
    - not found: the lost count goes up by one (saturating at ``lost_frames``). Below
      ``lost_frames`` the outputs hold; from ``lost_frames`` on they are the search command,
      turning in place towards ``last_side`` at ``search_dps`` (``left = +search_dps`` for
      right).

    After reset the outputs are 0, the lost count 0 and ``last_side`` left.

    The parameters that express the published design change this (``sim.model.MotorModel``
    and ``table_command`` are the reference): ``motor_law = "table"`` steers by the LED code
    with the ``steer_dps`` table instead of ``turn``; ``lost_motion = "drive"`` drives on below
    ``lost_frames`` at the frame's ``base_dps[proximity]``, steered by the last found frame's
    LED code; ``search_side_from = "leds"`` takes ``last_side`` from the LED code. None of it
    is elaborated at the defaults.

    Parameters
    ----------
    params : FollowTargetParams

    Members
    -------
    update : ``In(1)``
        The tracker's ``frame_done``.
    found : ``In(1)``
    proximity : ``In(3)``
    centroid_x : ``In(params.x_bits)``
    leds : ``In(8)``
        The tracker's results, valid while ``update`` is high (``leds``, the LED code, only
        when ``params.motor_uses_leds``).
    left, right : ``Out(signed(16))``
        Wheel speeds in DPS; they load at the edge that samples ``update``.
    last_side : ``Out(1)``
        1 when the target was last seen on the right half (``e >= 0``), 0 for left.
    lost_count : ``Out(range(lost_frames + 1))``
        Consecutive frames without the target, saturating at ``lost_frames``.
    """

    def __init__(self, params):
        if not isinstance(params, FollowTargetParams):
            raise TypeError(f"params must be a FollowTargetParams, not {params!r}")
        self.params = params
        leds = {"leds": In(8)} if params.motor_uses_leds else {}
        super().__init__(
            {
                "update": In(1),
                "found": In(1),
                "proximity": In(3),
                "centroid_x": In(params.x_bits),
                **leds,
                "left": Out(signed(DPS_BITS)),
                "right": Out(signed(DPS_BITS)),
                "last_side": Out(1),
                "lost_count": Out(range(params.lost_frames + 1)),
            }
        )

    @property
    def latency(self):
        """Outputs show the new values right after the edge that samples ``update``."""
        return 1

    def elaborate(self, platform):
        m = Module()
        p = self.params
        table = p.motor_law == "table"

        # e, turn and base +- turn are wide enough never to overflow before the saturation
        # (the published design lost bits here). e and turn are plain signals, each one net
        # for every use.
        if not table or p.search_side_from == "centroid":
            e_value = self.centroid_x - (p.width // 2)  # signed(x_bits + 1)
            e = Signal(e_value.shape())
            m.d.comb += e.eq(e_value)
        if not table:
            turn_value = (e * p.kp_num) >> p.kp_shift
            turn = Signal(turn_value.shape())
            m.d.comb += turn.eq(turn_value)

        # The base speed is a multiplexer tree on the proximity bits, rebuilt for each use
        # inside the `update` branch, not a case statement or an `Array` (a ROM read port):
        # three levels of 2:1 multiplexers over constants (why: docs/hardware.md).
        def base():
            values = [Const(v, signed(DPS_BITS)) for v in p.base_dps]
            for bit in range(3):
                values = [
                    Mux(self.proximity[bit], hi, lo) for lo, hi in zip(values[0::2], values[1::2])
                ]
            return values[0]

        def saturate(v):
            lim = p.max_dps
            return Mux(v > lim, lim, Mux(v < -lim, -lim, v))

        # Full-width constants: the selected one is the register's value as it is.
        search = Const(_wrap16(p.search_dps), signed(DPS_BITS))
        neg_search = Const(_wrap16(-p.search_dps), signed(DPS_BITS))

        # All of the controller's state in one register, loaded whole in each branch (one
        # enable for the wheel speeds and the lost-target state; see `fit`).
        fields = {
            "left": signed(DPS_BITS),
            "right": signed(DPS_BITS),
            "count": range(p.lost_frames + 1),
            "right_side": 1,
        }
        if p.lost_motion == "drive":
            fields["last_leds"] = 8  # the last found frame's LED code, 0 after reset
        state = Signal(data.StructLayout(fields))
        m.d.comb += [
            self.left.eq(state.left),
            self.right.eq(state.right),
            self.lost_count.eq(state.count),
            self.last_side.eq(state.right_side),
        ]

        if table:

            def command(code):
                return _table_command(p, base(), code, saturate)
        else:

            def command(code):
                return saturate(base() + turn), saturate(base() - turn)

        if p.search_side_from == "centroid":
            right_side = e >= 0
        else:
            code = self.leds
            centred = code[3] & code[4]
            right_side = Mux(centred, int(p.centred_search_side == "right"), code[4:8].any())

        with m.If(self.update):
            with m.If(self.found):
                left, right = command(self.leds if table else None)
                kept = {"last_leds": self.leds} if p.lost_motion == "drive" else {}
                m.d.sync += load(
                    state, left=left, right=right, count=0, right_side=right_side, **kept
                )
            # This frame reaches the limit (no constant-true comparison when it is 1: lint).
            with m.Elif(state.count >= p.lost_frames - 1 if p.lost_frames > 1 else 1):
                m.d.sync += load(
                    state,
                    left=Mux(state.right_side, search, neg_search),
                    right=Mux(state.right_side, neg_search, search),
                    count=p.lost_frames,
                )
            with m.Else():
                if p.lost_motion == "drive":
                    # On at this frame's speed, steered by the last found frame's LED code.
                    left, right = command(state.last_leds)
                    m.d.sync += load(state, left=left, right=right, count=state.count + 1)
                else:
                    m.d.sync += load(state, count=state.count + 1)
        return m


def _table_command(p, speed, code, saturate):
    """``(left, right)`` of the table law (``sim.model.table_command``) for a signed 16-bit
    ``speed`` and an LED ``code``, saturated to ``max_dps`` only where a value of the tables can
    exceed it."""
    centred = code[3] & code[4]
    target_left = code[0:4].any()
    # The outermost lit LED's distance from the centre picks the steering speed.
    near = [code[3 - d] | code[4 + d] for d in range(4)]
    steer = Const(p.steer_dps[0], unsigned(DPS_BITS - 1))
    for d in (1, 2, 3):
        steer = Mux(near[d], p.steer_dps[d], steer)
    backwards = speed[-1]
    slow = Mux(backwards, speed + steer, speed - steer)  # towards 0: no overflow
    if _table_can_exceed(p):
        speed, slow = saturate(speed), saturate(slow)
    # Forwards the wheel on the target's side is the slow one, backwards the other one.
    slow_left = target_left ^ backwards
    seen = code.any()  # not `code == 0`: Yosys writes `!code`, which the lint flags
    left = Mux(seen, Mux(centred | ~slow_left, speed, slow), 0)
    right = Mux(seen, Mux(centred | slow_left, speed, slow), 0)
    return left, right


def _table_can_exceed(p):
    """Whether a command of the table law can lie outside ``[-max_dps, max_dps]``."""
    values = set(p.base_dps)
    values |= {v + d if v < 0 else v - d for v in p.base_dps for d in p.steer_dps}
    return max(abs(v) for v in values) > p.max_dps
