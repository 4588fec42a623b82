"""``CorridorFollow``: keeps clear of the walls of a corridor by its LIDAR's nearest return."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .lidar_params import CorridorParams, NearestParams
from .motor import DPS_BITS
from .nearest_obstacle import NEAREST_MM_BITS, NearestObstacle, sample_stream
from .validate import CheckedArguments

__all__ = ["CorridorFollow", "corridor_command"]

_TURN_Q6 = 360 * 64


def corridor_command(params, found, nearest_mm, bearing_q6):
    """``(left, right)`` wheel command (DPS) for one revolution's nearest return: the control
    law of ``CorridorParams``."""
    p = params
    if not found:
        return p.base_dps, p.base_dps
    b = bearing_q6 if p.clockwise else (_TURN_Q6 - bearing_q6) % _TURN_Q6
    on_right = b < 180 * 64
    ahead = min(b, _TURN_Q6 - b)  # q6 off the robot's forward
    if nearest_mm < p.stop_mm and ahead < p.front_deg * 64:
        return (-p.turn_dps, p.turn_dps) if on_right else (p.turn_dps, -p.turn_dps)
    if nearest_mm < p.keep_mm and ahead <= p.side_deg * 64:
        if on_right:
            return p.base_dps - p.steer_dps, p.base_dps + p.steer_dps
        return p.base_dps + p.steer_dps, p.base_dps - p.steer_dps
    return p.base_dps, p.base_dps


class CorridorFollow(CheckedArguments, wiring.Component):
    """A ``NearestObstacle`` and the corridor law on its result (Verilog module
    ``corridor_follow``).

    The cycle after ``NearestObstacle``'s ``updated`` the wheel command register loads
    ``corridor_command`` of its outputs (``CorridorParams``): straight when nothing is near,
    steering away from a wall nearer than ``keep_mm``, turning in place away from an obstacle
    ahead nearer than ``stop_mm``. After reset the wheels stand still until the first
    revolution ends.

    Members
    -------
    lidar : ``In(stream.Signature(SampleLayout, always_ready=True))``, the LIDAR's samples
    motor_left, motor_right : ``Out(signed(16))``, DPS
    nearest_mm, bearing_q6, found : ``NearestObstacle``'s outputs
    """

    #: The LIDAR connector's pins on this design's ports.
    connectors = {"lidar": {"valid": "lidar__valid", "payload": "lidar__payload"}}  # noqa: RUF012

    @staticmethod
    def check_arguments(corridor=None, nearest=None):
        if corridor is not None and not isinstance(corridor, CorridorParams):
            raise TypeError(f"corridor must be a CorridorParams, not {corridor!r}")
        if nearest is not None and not isinstance(nearest, NearestParams):
            raise TypeError(f"nearest must be a NearestParams, not {nearest!r}")

    def __init__(self, corridor=None, nearest=None):
        self.params = CorridorParams() if corridor is None else corridor
        self.nearest_params = NearestParams() if nearest is None else nearest
        super().__init__(
            {
                "lidar": In(sample_stream()),
                "motor_left": Out(signed(DPS_BITS)),
                "motor_right": Out(signed(DPS_BITS)),
                "nearest_mm": Out(NEAREST_MM_BITS),
                "bearing_q6": Out(15),
                "found": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        p = self.params
        m.submodules.nearest = nearest = NearestObstacle(self.nearest_params)
        wiring.connect(m, wiring.flipped(self.lidar), nearest.samples)
        m.d.comb += [
            self.nearest_mm.eq(nearest.nearest_mm),
            self.bearing_q6.eq(nearest.bearing_q6),
            self.found.eq(nearest.found),
        ]

        b = Signal(15)  # the bearing, clockwise
        if p.clockwise:
            m.d.comb += b.eq(nearest.bearing_q6)
        else:  # the seeded bug: the bearing read counter-clockwise
            m.d.comb += b.eq(Mux(nearest.bearing_q6 == 0, 0, _TURN_Q6 - nearest.bearing_q6))
        on_right = Signal()
        ahead = Signal(15)  # off the robot's forward, either way
        m.d.comb += [
            on_right.eq(b < 180 * 64),
            ahead.eq(Mux(b <= 180 * 64, b, _TURN_Q6 - b)),
        ]
        left = Signal(signed(DPS_BITS))
        right = Signal(signed(DPS_BITS))
        m.d.comb += [self.motor_left.eq(left), self.motor_right.eq(right)]
        d = nearest.nearest_mm
        with m.If(nearest.updated):
            with m.If(~nearest.found):
                m.d.sync += [left.eq(p.base_dps), right.eq(p.base_dps)]
            with m.Elif((d < p.stop_mm) & (ahead < p.front_deg * 64)):
                with m.If(on_right):
                    m.d.sync += [left.eq(-p.turn_dps), right.eq(p.turn_dps)]
                with m.Else():
                    m.d.sync += [left.eq(p.turn_dps), right.eq(-p.turn_dps)]
            with m.Elif((d < p.keep_mm) & (ahead <= p.side_deg * 64)):
                with m.If(on_right):
                    m.d.sync += [
                        left.eq(p.base_dps - p.steer_dps),
                        right.eq(p.base_dps + p.steer_dps),
                    ]
                with m.Else():
                    m.d.sync += [
                        left.eq(p.base_dps + p.steer_dps),
                        right.eq(p.base_dps - p.steer_dps),
                    ]
            with m.Else():
                m.d.sync += [left.eq(p.base_dps), right.eq(p.base_dps)]
        return m
