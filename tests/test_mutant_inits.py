"""Initial values through ``mutate`` (sim.mutant_inits): a mutant on a register's output
leaves the register's start where the design has it, so the mutant netlist at ``mutsel = 0``
is the design from its first cycle, a design without a reset included."""

from pathlib import Path

import pytest
from toolchains import needs_mutation_toolchain

from fpga_robotics.designs.builtin import connector_kinds
from fpga_robotics.mutation.design import with_mutant_select
from fpga_robotics.mutation.pin_judge import pin_trace
from fpga_robotics.sim import mutation
from fpga_robotics.sim.backends.foreign import ForeignDesign
from fpga_robotics.sim.mutant_inits import restore_inits
from fpga_robotics.sim.pins.compiled import VerilatorPins
from fpga_robotics.sim.pins.verilog import VerilogPinSource

DATA = Path(__file__).parent / "data" / "init_regs"

# As Yosys writes a register q (initial value 2'01) after two mutants on its bit 0 and one on
# the output of an adder: the flip-flop drives w2, mutant 2's mux w1, mutant 1's mux q[0].
_RTLIL = r"""module \t
  wire input 1 \clk
  attribute \src "t.v:1"
  attribute \init 2'01
  wire width 2 output 2 \q
  wire $auto$mutate.cc:662:mutate_inv$1
  wire $auto$mutate.cc:662:mutate_inv$2
  wire $auto$mutate.cc:662:mutate_inv$3
  wire \sum
  cell $dff $procdff$1
    parameter \WIDTH 2
    connect \CLK \clk
    connect \D { \q [0] \sum }
    connect \Q { \q [1] $auto$mutate.cc:662:mutate_inv$2 }
  end
  cell $mux $m1
    connect \A $auto$mutate.cc:662:mutate_inv$1
    connect \B 1'0
    connect \S $s1
    connect \Y \q [0]
  end
  cell $mux $m2
    connect \A $auto$mutate.cc:662:mutate_inv$2
    connect \B 1'1
    connect \S $s2
    connect \Y $auto$mutate.cc:662:mutate_inv$1
  end
  cell $add $a
    connect \A \q [1]
    connect \B \q [0]
    connect \Y $auto$mutate.cc:662:mutate_inv$3
  end
  cell $mux $m3
    connect \A $auto$mutate.cc:662:mutate_inv$3
    connect \B 1'0
    connect \S $s3
    connect \Y \sum
  end
end
"""


def _init_of(rtlil, wire):
    lines = rtlil.splitlines()
    i = next(k for k, line in enumerate(lines) if line.endswith(f" {wire}"))
    attrs = []
    while lines[i - 1 - len(attrs)].startswith("  attribute "):
        attrs.append(lines[i - 1 - len(attrs)])
    return next((a.split()[-1] for a in attrs if a.startswith("  attribute \\init")), None)


def test_the_register_bit_behind_a_chain_of_mutants_gets_the_design_bits_start():
    out = restore_inits(_RTLIL, "t")
    assert _init_of(out, "$auto$mutate.cc:662:mutate_inv$2") == "1'1"  # q's bit 0
    # Driven by a mux or an adder, not a flip-flop: no initial value to keep.
    assert _init_of(out, "$auto$mutate.cc:662:mutate_inv$1") is None
    assert _init_of(out, "$auto$mutate.cc:662:mutate_inv$3") is None
    assert _init_of(out, "\\q") == "2'01"


def test_a_netlist_without_initial_values_is_left_as_it_is():
    text = _RTLIL.replace("  attribute \\init 2'01\n", "")
    assert restore_inits(text, "t") == text


def _pins(verilog, ports):
    design = ForeignDesign([verilog], ports, pins=True, connector_kinds=connector_kinds())
    return VerilatorPins(VerilogPinSource(design))


@pytest.mark.slow
@needs_mutation_toolchain
def test_the_mutant_netlist_at_mutsel_0_is_a_design_without_reset_from_its_first_cycle(tmp_path):
    original = ForeignDesign(
        [DATA / "init_regs.v"],
        DATA / "init_regs_ports.toml",
        pins=True,
        connector_kinds=connector_kinds(),
    )
    sources = {"verilog": original.sources, "top": "init_regs", "includes": original.includes}
    mutants = mutation.list_mutants(None, 40, 1, **sources)
    on_registers = [m for m in mutants if m.port == "Q"]
    assert len(on_registers) >= 3  # the case at stake: mutants on the registers' outputs
    netlist = tmp_path / "mutants.v"
    netlist.write_text(mutation.mutant_netlist(None, mutants, watch=False, **sources))
    ports = tmp_path / "mutants_ports.toml"
    ports.write_text(with_mutant_select((DATA / "init_regs_ports.toml").read_text()))
    outputs = ["motor_left", "motor_right"]
    design = VerilatorPins(VerilogPinSource(original))
    try:
        design.reset()
        design.watch(outputs)
        expected = {name: [(0, design.peek(name))] for name in outputs}
        while design.cycle < 300:
            design.run(300 - design.cycle)
            for name in outputs:
                if expected[name][-1][1] != design.peek(name):
                    expected[name].append((design.cycle, design.peek(name)))
    finally:
        design.close()
    # By hand: the reset's one edge moves the LFSR a step from 0xA5C3 (feedback 1^1^0^1).
    assert expected["motor_left"][0] == (0, 0x4B87)
    mutated = _pins(netlist, ports)
    try:
        assert pin_trace(mutated, 0, [], 300, outputs) == expected
    finally:
        mutated.close()
