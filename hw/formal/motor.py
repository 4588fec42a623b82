"""The motor controller's promises: the wheel speeds never leave ``+-max_dps`` (when
``abs(search_dps) <= max_dps``: the search speed is not clamped), and a frame without the
target holds the command until ``lost_frames`` such frames in a row, after which it is the
search command towards the side where the target was last seen.

The reference state (lost count, last side, last command) is kept here from the inputs, as
the contract states it; its lost count and side are compared with the controller's outputs
on every cycle, which makes the proof inductive (it holds for ever, not for a bounded run).
"""

from amaranth.asserts import AnySeq
from amaranth.hdl import Assert, Cover, Mux, Signal, signed

from ..motor import MotorController
from .harness import Harness
from .sizes import FULL_SIZES

__all__ = ["MotorHarness"]


class MotorHarness(Harness):
    """``MotorController`` with free inputs on every cycle (``update`` any time)."""

    def __init__(self, dut=None, params=FULL_SIZES["160x120"]):
        super().__init__()
        self.dut = MotorController(params) if dut is None else dut
        p = self.dut.params
        if p.lost_motion != "hold" or abs(p.search_dps) > p.max_dps:
            raise ValueError(
                "the motor promises are stated for lost_motion='hold' and "
                "abs(search_dps) <= max_dps"
            )

    def check(self, m):
        dut, p = self.dut, self.dut.params
        m.submodules.dut = dut
        m.d.comb += [
            dut.update.eq(AnySeq(1)),
            dut.found.eq(AnySeq(1)),
            dut.proximity.eq(AnySeq(3)),
            dut.centroid_x.eq(AnySeq(p.x_bits)),
        ]
        if p.motor_uses_leds:
            m.d.comb += dut.leds.eq(AnySeq(8))

        for wheel in (dut.left, dut.right):
            m.d.comb += Assert(
                (wheel <= p.max_dps) & (wheel >= -p.max_dps), "wheel speed beyond max_dps"
            )

        # The contract's state, from the inputs alone.
        lost = Signal(range(p.lost_frames + 1))
        right_side = Signal()
        m.d.comb += [
            Assert(dut.lost_count == lost, "lost count is not the frames without target"),
            Assert(dut.last_side == right_side, "last side is not where the target was"),
        ]
        # What the outputs must be after the update now on the input: `expect_*` when `check`.
        check = Signal()
        expect_left = Signal(signed(16))
        expect_right = Signal(signed(16))
        m.d.sync += check.eq(0)
        with m.If(dut.update):
            with m.If(dut.found):
                m.d.sync += [lost.eq(0), right_side.eq(dut.centroid_x >= p.width // 2)]
            with m.Else():
                after = Mux(lost == p.lost_frames, lost, lost + 1)
                m.d.sync += [lost.eq(after), check.eq(1)]
                with m.If(after < p.lost_frames):  # hold
                    m.d.sync += [expect_left.eq(dut.left), expect_right.eq(dut.right)]
                with m.Else():  # search towards the last side
                    turn = Mux(right_side, p.search_dps, -p.search_dps)
                    m.d.sync += [expect_left.eq(turn), expect_right.eq(-turn)]
        with m.If(check):
            m.d.comb += Assert(
                (dut.left == expect_left) & (dut.right == expect_right),
                "lost frame: neither held nor searching",
            )
        m.d.comb += [
            Cover(check & (lost == p.lost_frames) & (dut.left == p.search_dps)),
            Cover(check & (lost == p.lost_frames) & (dut.left == -p.search_dps)),
            Cover(dut.left == p.max_dps),
            Cover(dut.right == -p.max_dps),
        ]
