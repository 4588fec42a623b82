"""``CorridorFollowUart``: ``CorridorFollow`` fed by the LIDAR's own serial link."""

from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .corridor_follow import CorridorFollow
from .lidar_params import CorridorParams, NearestParams, UartParams
from .lidar_uart import RplidarDecoder, UartRx
from .motor import DPS_BITS
from .validate import CheckedArguments

__all__ = ["CorridorFollowUart"]


class CorridorFollowUart(CheckedArguments, wiring.Component):
    """``UartRx`` -> ``RplidarDecoder`` -> ``CorridorFollow`` (Verilog module
    ``corridor_follow_uart``): the same law on the samples decoded from ``lidar_rx`` (8N1 at
    ``UartParams.baud``), which reach it a packet's transmission (434 us at 115200 baud) and
    a few cycles later than on the stream binding.

    Members
    -------
    lidar_rx : ``In(1)``, the LIDAR's TX line (idle high)
    motor_left, motor_right, nearest_mm, bearing_q6, found : ``CorridorFollow``'s
    framing_errors : ``Out(8)``, bytes whose stop bit was low (wrapping)
    resyncs : ``Out(8)``, bytes the decoder dropped to find a packet's start (wrapping)
    """

    connectors = {"lidar_uart": {"rx": "lidar_rx"}}  # noqa: RUF012

    @staticmethod
    def check_arguments(corridor=None, nearest=None, uart=None):
        CorridorFollow.check_arguments(corridor, nearest)
        if uart is not None and not isinstance(uart, UartParams):
            raise TypeError(f"uart must be a UartParams, not {uart!r}")

    def __init__(self, corridor=None, nearest=None, uart=None):
        self.corridor_params = CorridorParams() if corridor is None else corridor
        self.nearest_params = NearestParams() if nearest is None else nearest
        self.uart_params = UartParams() if uart is None else uart
        super().__init__(
            {
                "lidar_rx": In(1, init=1),
                "motor_left": Out(signed(DPS_BITS)),
                "motor_right": Out(signed(DPS_BITS)),
                "nearest_mm": Out(14),
                "bearing_q6": Out(15),
                "found": Out(1),
                "framing_errors": Out(8),
                "resyncs": Out(8),
            }
        )

    def elaborate(self, platform):
        m = Module()
        m.submodules.uart = uart = UartRx(self.uart_params)
        m.submodules.decoder = decoder = RplidarDecoder()
        m.submodules.follow = follow = CorridorFollow(self.corridor_params, self.nearest_params)
        m.d.comb += uart.rx.eq(self.lidar_rx)
        wiring.connect(m, uart.bytes, decoder.bytes)
        wiring.connect(m, decoder.samples, follow.lidar)
        for name in ("motor_left", "motor_right", "nearest_mm", "bearing_q6", "found"):
            m.d.comb += getattr(self, name).eq(getattr(follow, name))
        m.d.comb += self.resyncs.eq(decoder.resyncs)
        with m.If(uart.framing_error):
            m.d.sync += self.framing_errors.eq(self.framing_errors + 1)
        return m
