"""Sequential (restoring) integer divider: one quotient bit per clock cycle."""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from .fit import load
from .validate import CheckedArguments, check_int

__all__ = ["SequentialDivider"]


class SequentialDivider(CheckedArguments, wiring.Component):
    """Unsigned ``dividend // divisor`` for a quotient known to fit ``quotient_bits`` bits.

    Only ``quotient_bits`` steps are needed, not ``dividend_bits``: the partial remainder starts
    as ``dividend >> quotient_bits``, which is below ``divisor`` when the quotient fits. The
    caller guarantees ``dividend < divisor << quotient_bits`` (the centroid ``SX // N`` is at
    most ``width - 1``); otherwise, or for a zero divisor, ``quotient`` is meaningless but the
    divider still finishes on time.

    Parameters
    ----------
    dividend_bits, divisor_bits, quotient_bits : int
        Operand and result widths (each at least 1).
    tag_bits : int, optional
        Width of a tag that travels with the division (default 0: none). A caller with
        results of its own to deliver with the quotient keeps them here rather than in a
        register of its own (the tag shares the divider's state register and its enable).

    Members
    -------
    start : ``In(1)``
        Load ``dividend`` and ``divisor`` (sampled at this edge only: they may change
        afterwards) and begin; a ``start`` while busy restarts.
    dividend : ``In(dividend_bits)``
    divisor : ``In(divisor_bits)``
    quotient : ``Out(quotient_bits)``
        Valid from ``done`` until the next ``start``.
    busy : ``Out(1)``
        High while steps remain.
    done : ``Out(1)``
        One-cycle strobe: right after edge S + ``latency`` when ``start`` was sampled at edge S.
    tag_in : ``In(tag_bits)``
        Sampled with ``start`` (only with ``tag_bits``).
    tag : ``Out(tag_bits)``
        The ``tag_in`` of the last ``start``, from the next edge until the next ``start``.
    """

    @staticmethod
    def check_arguments(dividend_bits, divisor_bits, quotient_bits, *, tag_bits=0):
        """Raise ``TypeError``/``ValueError`` unless the constructor accepts the arguments."""
        check_int("dividend_bits", dividend_bits, 1)
        check_int("divisor_bits", divisor_bits, 1)
        check_int("quotient_bits", quotient_bits, 1)
        check_int("tag_bits", tag_bits, 0)

    def __init__(self, dividend_bits, divisor_bits, quotient_bits, *, tag_bits=0):
        self.dividend_bits = int(dividend_bits)
        self.divisor_bits = int(divisor_bits)
        self.quotient_bits = int(quotient_bits)
        self.tag_bits = int(tag_bits)
        members = {
            "start": In(1),
            "dividend": In(dividend_bits),
            "divisor": In(divisor_bits),
            "quotient": Out(quotient_bits),
            "busy": Out(1),
            "done": Out(1),
        }
        if tag_bits:
            members.update(tag_in=In(tag_bits), tag=Out(tag_bits))
        super().__init__(members)

    @property
    def latency(self):
        """Cycles from the ``start`` edge to the edge after which ``done`` is high."""
        return self.quotient_bits

    def elaborate(self, platform):
        m = Module()
        q_bits = self.quotient_bits

        # One packed register, loaded whole in each branch (see `fit`).
        # `steps` is q_bits + 1 at the start, a step is taken while it is above 1, and 1 is
        # the `done` cycle, so `done` needs no register of its own.
        state = Signal(
            data.StructLayout(
                {
                    "steps": range(q_bits + 2),
                    "rem": self.divisor_bits,  # partial remainder, always < divisor
                    "low": q_bits,  # dividend bits still to bring down; quotient bits shift in
                    "divisor": self.divisor_bits,  # held: the inputs may change once started
                    "tag": self.tag_bits,
                }
            )
        )
        steps, rem, low, divisor = state.steps, state.rem, state.low, state.divisor
        if self.tag_bits:
            m.d.comb += self.tag.eq(state.tag)

        trial = Cat(low[-1], rem)  # rem * 2 + next dividend bit
        fits = trial >= divisor

        stepping = steps > 1  # as fast as testing the bits above bit 0 (docs/hardware.md)
        m.d.comb += [
            self.quotient.eq(low),
            self.busy.eq(stepping),
            self.done.eq(steps == 1),
        ]
        # Each branch loads the whole register in one assignment (see `load`).
        with m.If(self.start):
            tag_value = {"tag": self.tag_in} if self.tag_bits else {}
            m.d.sync += load(
                state,
                steps=q_bits + 1,
                rem=self.dividend >> q_bits,
                low=self.dividend[:q_bits],
                divisor=self.divisor,
                **tag_value,
            )
        with m.Elif(steps != 0):  # idle (most clocks) costs this one test
            with m.If(stepping):
                m.d.sync += load(
                    state,
                    steps=steps - 1,
                    rem=Mux(fits, trial - divisor, trial),
                    low=Cat(fits, low[:-1]),
                )
            with m.Else():
                m.d.sync += load(state, steps=0)  # the `done` cycle
        return m
