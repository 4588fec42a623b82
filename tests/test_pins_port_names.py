"""Port names that are C++ keywords (``delete``, ``class``, ``int``, ``register``, ``new``),
words Verilator reserves (``near``, ``far``) or names of the harness and model classes
(``top``, ``eval``) run on every pin backend: a seeded script of pokes, watches and runs
gives, on pysim, cxxrtl and verilator, the values of a Python model of the design written
here. Every ``run`` is bounded (the watchdog of these testbenches).
"""

import numpy as np
import pytest
from amaranth import Module, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from fpga_robotics.sim.pins import PinDesignSource, PinError, Stop, get_pin_backend

BACKENDS = ["pysim", "cxxrtl", "verilator"]


class Reserved(wiring.Component):
    """``near`` adds ``delete`` at every edge that samples ``class`` high; ``register``
    samples ``top``; ``eval`` counts edges. ``far = near ^ 0x55``, ``int = delete`` and
    ``new = -near`` are combinational."""

    def __init__(self):
        super().__init__(
            wiring.Signature(
                {
                    "delete": In(4),
                    "class": In(1),
                    "top": In(1),
                    "near": Out(8),
                    "far": Out(8),
                    "int": Out(4),
                    "register": Out(1),
                    "eval": Out(8),
                    "new": Out(signed(8)),
                }
            )
        )

    def elaborate(self, platform):
        m = Module()
        p = {name: getattr(self, name) for name in self.signature.members}
        with m.If(p["class"]):
            m.d.sync += p["near"].eq(p["near"] + p["delete"])
        m.d.sync += [p["register"].eq(p["top"]), p["eval"].eq(p["eval"] + 1)]
        m.d.comb += [
            p["far"].eq(p["near"] ^ 0x55),
            p["int"].eq(p["delete"]),
            p["new"].eq(-p["near"]),
        ]
        return m


SOURCE = PinDesignSource(Reserved, "test_pins_reserved_names")
INPUTS = ("delete", "class", "top")
OUTPUTS = ("near", "far", "int", "register", "eval", "new")


class Model:
    """The design in Python: the state after each edge."""

    def __init__(self):
        self.inputs = dict.fromkeys(INPUTS, 0)
        self.near = self.register = self.eval = 0

    def edge(self):
        if self.inputs["class"]:
            self.near = (self.near + self.inputs["delete"]) & 0xFF
        self.register = self.inputs["top"]
        self.eval = (self.eval + 1) & 0xFF

    def peek(self, name):
        if name in INPUTS:
            return self.inputs[name]
        new = -self.near & 0xFF
        return {
            "near": self.near,
            "far": self.near ^ 0x55,
            "int": self.inputs["delete"],
            "register": self.register,
            "eval": self.eval,
            "new": new - 256 if new & 0x80 else new,
        }[name]


def _script(pins, seed):
    rng = np.random.default_rng(seed)
    pins.reset()
    log = []
    for _ in range(50):
        name = INPUTS[int(rng.integers(len(INPUTS)))]
        pins.poke(name, int(rng.integers(16 if name == "delete" else 2)))
        if rng.integers(3) == 0:
            pins.watch([str(n) for n in rng.choice(OUTPUTS, 2, replace=False)])
        else:
            pins.watch([])
        stop = pins.run(int(rng.integers(1, 9)))
        log.append((stop, {n: pins.peek(n) for n in pins.ports}))
    return log


def test_the_ports_keep_their_names():
    assert list(SOURCE.ports) == [*INPUTS, *OUTPUTS]
    assert SOURCE.ports["new"].signed


@pytest.mark.parametrize(
    "name",
    [pytest.param(b, marks=pytest.mark.slow) if b == "verilator" else b for b in BACKENDS],
)
def test_reserved_names_run_as_the_model_says(name):
    model = Model()
    with get_pin_backend(name, SOURCE) as pins:
        pins.reset()
        cycle = 0
        for step, (delete, cls, top, edges) in enumerate(
            [(3, 1, 1, 5), (9, 0, 0, 2), (15, 1, 0, 20), (1, 1, 1, 1)]
        ):
            for port, value in (("delete", delete), ("class", cls), ("top", top)):
                pins.poke(port, value)
                model.inputs[port] = value
            cycle += edges
            assert pins.run(edges) == Stop(cycle), step
            for _ in range(edges):
                model.edge()
            assert {n: pins.peek(n) for n in SOURCE.ports} == {
                n: model.peek(n) for n in SOURCE.ports
            }, step


@pytest.mark.slow  # builds the Verilator pin model
def test_a_seeded_script_is_the_same_on_every_backend():
    logs = {}
    for name in BACKENDS:
        with get_pin_backend(name, SOURCE) as pins:
            logs[name] = _script(pins, 11)
    assert any(stop.port for stop, _ in logs["pysim"])  # the script does stop on changes
    assert logs["cxxrtl"] == logs["pysim"]
    assert logs["verilator"] == logs["pysim"]


class ClockNamed(wiring.Component):
    clk: Out(1)

    def elaborate(self, platform):
        return Module()


def test_a_port_named_like_the_clock_is_a_clear_error():
    with pytest.raises(PinError, match="port named 'clk'.*rename the port"):
        PinDesignSource(ClockNamed, "test_pins_clock_named")
