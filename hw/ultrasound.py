"""``UltrasoundDriver``: trigger generator, echo width counter and distance in mm for an
HC-SR04 ultrasound module."""

from amaranth import Module, Signal
from amaranth.lib import enum, wiring
from amaranth.lib.wiring import In, Out

from .sensor_params import DISTANCE_BITS, DISTANCE_NONE, UltrasoundParams
from .validate import CheckedArguments

__all__ = ["UltrasoundDriver", "UltrasoundParams"]


class _State(enum.Enum, shape=2):
    IDLE = 0  # between measurements
    WAIT = 1  # TRIG has fallen: waiting for the echo to start
    COUNT = 2  # counting the echo's cycles


class UltrasoundDriver(CheckedArguments, wiring.Component):
    """Drives an HC-SR04: a TRIG pulse every period, then the width of the ECHO pulse in
    clock cycles, converted to millimetres.

    Cycle numbering as ``sim/pins/base.py``: edge 0 is the reset, ``P = period_cycles``,
    ``T = trigger_cycles``, ``W = wait_cycles``, ``M = max_echo_cycles``; "after edge e" is a
    value settled right after rising edge ``e``; ECHO "sampled at edge e" is its value just
    before that edge.

    - **TRIG** is high after edges ``k*P + 1 .. k*P + T`` for k = 0, 1, ...: it rises after
      edge 1 (the first edge after reset), lasts exactly ``T`` cycles and falls after edge
      ``E0 = k*P + T + 1``.
    - **ECHO** passes a two-flop synchroniser (inverted first when ``echo_active_high`` is
      False). An echo that is high when sampled at edges ``a .. b-1`` (rising before edge
      ``a``, falling before edge ``b``) is seen to start at edge ``a + 2``; it counts when
      ``E0 + 1 <= a + 2 <= E0 + W`` (a rising edge of the synchronised echo, so an ECHO
      already high when TRIG falls does not count). Its width is ``b - a`` cycles.
    - **Measurement.** If ``b - a <= M``: ``distance_mm = ((b - a) * distance_k) >>
      distance_shift``, ``no_echo = 0``, shown after edge ``b + 2`` (two synchroniser flops
      and one register after the echo's fall) with ``measured`` high after that edge only.
      If the echo is longer than ``M``: ``no_echo = 1``, ``distance_mm = 65535``, shown with
      ``measured`` after edge ``a + M + 2`` (the echo's remaining cycles are ignored). If no
      echo starts by edge ``E0 + W``: the same "no echo" result after edge ``E0 + W``.
      Every period thus gives exactly one ``measured`` strobe, before the next TRIG.
    - ``distance_mm`` and ``no_echo`` hold until the next measurement; after reset they are
      0 and ``measured`` has not pulsed.

    With ``echo_bits`` narrower than ``full_echo_bits`` the counter wraps modulo
    ``2**echo_bits`` and never reaches ``M``: the distance is that of the wrapped count
    (``UltrasoundParams.distance_of``) and long echoes are never "no echo" (a seeded bug).

    Parameters
    ----------
    params : UltrasoundParams, optional

    Members
    -------
    trig : ``Out(1)``
        The module's TRIG input.
    echo : ``In(1)``
        The module's ECHO output (asynchronous).
    distance_mm : ``Out(16)``
        The last measurement's distance (mm); 65535 after "no echo".
    measured : ``Out(1)``
        One-cycle strobe: ``distance_mm`` and ``no_echo`` show a new measurement.
    no_echo : ``Out(1)``
        The last measurement found nothing in range (echo too long, or none).
    """

    @staticmethod
    def check_arguments(params=None):
        if params is not None and not isinstance(params, UltrasoundParams):
            raise TypeError(f"params must be an UltrasoundParams, not {params!r}")

    def __init__(self, params=None):
        self.params = params = UltrasoundParams() if params is None else params
        super().__init__(
            {
                "trig": Out(1),
                "echo": In(1),
                "distance_mm": Out(DISTANCE_BITS),
                "measured": Out(1),
                "no_echo": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        p = self.params
        T, W, M = p.trigger_cycles, p.wait_cycles, p.max_echo_cycles

        # Free-running phase of the measurement period: e mod P after edge e.
        phase = Signal(range(p.period_cycles))
        m.d.sync += phase.eq(phase + 1)
        with m.If(phase == p.period_cycles - 1):
            m.d.sync += phase.eq(0)
        # Registered, so that TRIG never glitches on the wire.
        m.d.sync += self.trig.eq(phase < T)

        # Two flops against metastability, a third to see the echo's rising edge.
        echo_in = self.echo if p.echo_active_high else ~self.echo
        sync1, sync2, prev = Signal(), Signal(), Signal()
        m.d.sync += [sync1.eq(echo_in), sync2.eq(sync1), prev.eq(sync2)]
        rising = sync2 & ~prev

        state = Signal(_State)
        count = Signal(p.counter_bits)
        m.d.sync += self.measured.eq(0)

        def no_echo():
            m.d.sync += [
                state.eq(_State.IDLE),
                self.no_echo.eq(1),
                self.distance_mm.eq(DISTANCE_NONE),
                self.measured.eq(1),
            ]

        with m.Switch(state):
            with m.Case(_State.IDLE), m.If(phase == T):  # the edge at which TRIG falls
                m.d.sync += state.eq(_State.WAIT)
            with m.Case(_State.WAIT):
                with m.If(rising):
                    m.d.sync += [state.eq(_State.COUNT), count.eq(1)]
                with m.Elif(phase == T + W):
                    no_echo()
            with m.Default():  # COUNT (Default: no uncovered state value in the Verilog)
                with m.If(~sync2):
                    m.d.sync += [
                        state.eq(_State.IDLE),
                        self.distance_mm.eq((count * p.distance_k) >> p.distance_shift),
                        self.no_echo.eq(0),
                        self.measured.eq(1),
                    ]
                with m.Elif(count == M):  # one cycle longer than the longest echo
                    no_echo()
                with m.Else():
                    m.d.sync += count.eq(count + 1)
        return m
