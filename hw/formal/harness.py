"""What every formal harness shares: the clock, delayed values, the record of a check.

A harness is the top of one formal run. It drives the design under test from ``AnySeq`` /
``AnyConst`` inputs (free values the solver picks: every input sequence at once), constrains
only those inputs with ``Assume``, and states the promise with ``Assert`` (or ``Cover``).

The ``sync`` domain is reset-less here: every register starts at its ``init`` value, which is
the state the design's reset puts it in, and the solver explores every input from there.
The clock must be a port of the top: without one Yosys ties it to 0, nothing ever moves and
every assertion would hold vacuously (the covers of each harness catch that).
"""

from collections.abc import Callable
from dataclasses import dataclass, field

from amaranth.hdl import ClockDomain, Elaboratable, Module, Signal, Value

__all__ = ["MODES", "FormalCheck", "Harness", "delayed"]

#: ``prove``: k-induction (holds in every reachable state, for ever); ``bmc``: holds in every
#: state reachable within ``depth`` cycles of reset; ``cover``: each ``Cover`` is reachable
#: within ``depth`` cycles.
MODES = ("prove", "bmc", "cover")


@dataclass(frozen=True)
class FormalCheck:
    """One formal run: a harness, how to check it, and what it shows.

    ``build(dut)`` returns the harness top around ``dut``, or around the real design when
    ``dut`` is ``None`` (tests pass a copy of the design with a seeded bug). ``make_dut()``
    builds that real design, so a test can change a copy of it.
    """

    name: str
    mode: str
    depth: int
    promise: str
    build: Callable = field(repr=False)
    make_dut: Callable = field(repr=False)

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"mode must be one of {', '.join(MODES)}, not {self.mode!r}")


class Harness(Elaboratable):
    """Base of the harnesses: the reset-less ``sync`` domain and the ports of the top.

    Subclasses implement ``check(m)``, adding the design and the properties to ``m``.
    """

    def __init__(self):
        self.sync = ClockDomain("sync", reset_less=True)
        self.clocks = [self.sync]

    def ports(self):
        """The top's ports: its clocks (every other input is an ``AnySeq``/``AnyConst``)."""
        return [cd.clk for cd in self.clocks]

    def elaborate(self, platform):
        m = Module()
        for cd in self.clocks:
            m.domains += cd
        self.check(m)
        return m

    def check(self, m):
        raise NotImplementedError


def delayed(m, value, cycles, *, domain="sync", init=0):
    """``value`` as it was ``cycles`` clock edges ago (``init`` before that)."""
    for _ in range(cycles):
        reg = Signal(Value.cast(value).shape(), init=init, name="past")
        m.d[domain] += reg.eq(value)
        value = reg
    return value
