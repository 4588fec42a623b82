"""A pin design's ``[watch]`` output (a mutant netlist's ``mutinf``): the bits that rose since
the reset, however wide the output (pin ports carry 64 bits at most, so the wrapper gives it
out in pieces), read by ``watch_risen`` once each."""

from pathlib import Path

import pytest

from fpga_robotics.designs.builtin import connector_kinds
from fpga_robotics.sim.backends.foreign import ForeignDesign
from fpga_robotics.sim.pins import get_pin_backend
from fpga_robotics.sim.pins.verilog import VerilogPinSource

DATA = Path(__file__).parent / "data" / "watch_wide"


def _backend(name):
    design = ForeignDesign(
        [DATA / "watch_wide.v"],
        DATA / "watch_wide_ports.toml",
        pins=True,
        connector_kinds=connector_kinds(),
    )
    return get_pin_backend(name, VerilogPinSource(design))


@pytest.mark.parametrize("name", ["cxxrtl", pytest.param("verilator", marks=pytest.mark.slow)])
def test_the_bits_of_a_wide_watch_rise_once_each(name):
    with _backend(name) as pins:
        assert [p for p in pins.ports if p.startswith("fr_watch_any_")] == [
            "fr_watch_any_0",
            "fr_watch_any_1",
        ]
        assert (pins.ports["fr_watch_any_0"].width, pins.ports["fr_watch_any_1"].width) == (64, 6)
        pins.reset()
        assert pins.watch_risen() == []
        # The counter is e after edge e: bit 0 is high at edge 3 only, and stays risen.
        pins.run(10)
        assert pins.watch_risen() == [0]
        pins.run(15)  # to edge 25: bit 64 rose at edge 20
        assert pins.watch_risen() == [64]
        assert pins.watch_risen() == []  # given once
        pins.run(100)
        assert pins.watch_risen() == [69]
        # The reset clears them: all three again, in bit order.
        pins.reset()
        pins.run(50)
        assert pins.watch_risen() == [0, 64, 69]


def test_a_design_without_a_watch_has_none():
    design = ForeignDesign(
        [Path(__file__).parent / "data" / "bump_stop.v"],
        Path(__file__).parent / "data" / "bump_stop_ports.toml",
        pins=True,
        connector_kinds=connector_kinds(),
    )
    with get_pin_backend("cxxrtl", VerilogPinSource(design)) as pins:
        pins.reset()
        pins.run(5)
        assert pins.watch_risen() is None
        assert not any(p.startswith("fr_watch_any") for p in pins.ports)
