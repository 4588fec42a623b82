"""What the CXXRTL harness reads from a generated model (cxxrtl_netlist): output expressions,
the commit list, and the two rewrites of the one-evaluation build, checked on the real
generated models, on small hand-written models, and by running the rewritten build against
the unrewritten (waveform) build frame by frame."""

import re

import numpy as np
import pytest
from test_backends_equivalence import SMALL_A, assert_same, frame_sequence

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import WaveformRequest, get_backend
from fpga_robotics.sim.backends.cxxrtl_netlist import (
    OUTPUTS,
    commit_wires,
    model_header,
    output_sources,
    with_wire_copies_inlined,
    without_port_copies,
)
from fpga_robotics.sim.backends.designs import DesignSource


def eval_body(source):
    start = source.index("::eval(performer *performer) {")
    return source[start : source.index("\n}\n", start)]


def struct_wires(source):
    return set(re.findall(r"^\t(?:/\*\w+\*/ )?wire<\d+> (\w+);$", source, re.MULTILINE))


@pytest.fixture(scope="module")
def follow_target_source():
    return DesignSource(FollowTargetParams()).cxxrtl()


def test_follow_target_outputs_are_expressions_of_flip_flops_only(follow_target_source):
    sources = output_sources(follow_target_source)
    assert sources is not None and set(sources) == set(OUTPUTS)
    wires = struct_wires(follow_target_source)
    for port, expr in sources.items():
        members = re.findall(r"\bt\.(\w+)\.curr\b", expr)
        assert members, port
        assert set(members) <= wires, port
        # Nothing but flip-flop reads, slices and constants: no input port, no local.
        assert not re.search(r"\b(?<!t\.)[pi]_\w+", expr), (port, expr)


def test_commit_list_is_every_wire_of_the_model(follow_target_source):
    assert set(commit_wires(follow_target_source)) == struct_wires(follow_target_source)
    header = model_header(follow_target_source)
    assert "#define FR_REGISTERED_OUTPUTS 1" in header
    assert "#define FR_COMMIT(t)" in header
    for port in OUTPUTS:
        assert f"#define FR_OUT_{port.upper()}(t)" in header


def test_combinational_outputs_keep_the_general_loop():
    source = DesignSource(FollowTargetParams(width=40, height=16), "passthrough_comb").cxxrtl()
    assert output_sources(source) is None
    header = model_header(source)
    assert "FR_REGISTERED_OUTPUTS" not in header and "FR_COMMIT" not in header
    assert without_port_copies(source) == source


def test_port_copies_are_removed_and_nothing_else(follow_target_source):
    stripped = without_port_copies(follow_target_source)
    body, before = eval_body(stripped), eval_body(follow_target_source)
    removed = [line for line in before.splitlines() if line not in body.splitlines()]
    assert len(removed) == len(OUTPUTS)
    for port in OUTPUTS:
        name = "p_" + port.replace("_", "__")
        assert not re.search(rf"^\t{name} = ", body, re.MULTILINE)
    # Only eval() changed: what comes before and after it is the generated text as it was.
    start = follow_target_source.index(before)
    assert stripped[:start] == follow_target_source[:start]
    assert stripped[start + len(body) :] == follow_target_source[start + len(before) :]


HAND_MODEL = """
struct p_top : public module {
\twire<112> p_bins;
\twire<8> p_small;
\t/*output*/ value<8> p_out;
};
bool p_top::eval(performer *performer) {
\tbool converged = true;
\tvalue<112> p_copy;
\tvalue<8> p_narrow;
\tvalue<8> p_twice;
\tp_copy = p_bins.curr;
\tp_narrow = p_bins.curr;
\tp_twice = p_small.curr;
\tp_twice = p_small.curr.slice<3,0>().val();
\tif (posedge_p_clk) {
\t\tp_small.next = p_copy.slice<7,0>().val() + p_narrow + p_twice;
\t}
\treturn converged;
}
"""


def test_wire_copies_are_inlined_only_when_it_is_the_same_value():
    rewritten = eval_body(with_wire_copies_inlined(HAND_MODEL))
    # The whole-wire copy into a same-width local is gone, its readers read the wire.
    assert "p_copy" not in rewritten
    assert "p_small.next = p_bins.curr.slice<7,0>().val() + p_narrow + p_twice;" in rewritten
    # A narrower local (a truncation) and a local assigned twice are left alone.
    assert "\tp_narrow = p_bins.curr;" in rewritten
    assert "\tp_twice = p_small.curr;" in rewritten


def test_commit_with_anything_but_wires_is_not_replaced():
    source = """
\ttemplate<class ObserverT>
\tbool commit(ObserverT &observer) {
\t\tbool changed = false;
\t\tif (p_a.commit(observer)) changed = true;
\t\tif (memory_p_m.commit(observer)) changed = true;
\t\tprev_p_clk = p_clk;
\t\treturn changed;
\t}
"""
    assert commit_wires(source) is None
    wires = "\twire<1> p_a;\n\twire<2> p_b;\n"
    assert commit_wires(wires + source) is None
    assert commit_wires(wires + source.replace("memory_p_m", "p_b")) == ["p_a", "p_b"]


def test_rewritten_build_matches_the_waveform_build(tmp_path):
    """The one-evaluation build (outputs from flip-flops, commit by copies, rewrites) against
    the two-evaluation traced build of the unrewritten model, every frame traced."""
    seq = frame_sequence(SMALL_A, seed=5)
    with get_backend("cxxrtl", SMALL_A) as plain:
        assert plain.evals_per_cycle == 1
        fast = [plain.process_frame(f, c) for f, c in seq]
    request = WaveformRequest(tmp_path / "all.vcd", first_frame=0, last_frame=len(seq) - 1)
    with get_backend("cxxrtl", SMALL_A, waveform=request) as traced:
        assert traced.evals_per_cycle == 2
        slow = [traced.process_frame(f, c) for f, c in seq]
    assert_same(slow, fast, "cxxrtl one-evaluation build")
    assert any(r.found for r in fast) and any(not r.found for r in fast)
    assert len({r.motor_left for r in fast}) > 2
    assert np.any(fast[-2].filtered)


def test_a_clock_the_design_drives_is_refused_by_the_cxxrtl_frame_build():
    # A divider's register clocking a counter (a Verilog design on the CXXRTL frame
    # backend): CXXRTL never sees its edges (Yosys issue #3549), the counter would stay 0.
    from amaranth import ClockDomain, ClockSignal, Module, Signal
    from amaranth.lib import wiring
    from amaranth.lib.wiring import Out

    from fpga_robotics.hw.verilog import generate_cxxrtl
    from fpga_robotics.sim.backends.base import BackendError
    from fpga_robotics.sim.backends.cxxrtl import cxxrtl_build_plan

    class HalfClock(wiring.Component):
        ticks: Out(8)

        def elaborate(self, platform):
            m = Module()
            m.domains.half = ClockDomain()
            divider = Signal()
            m.d.sync += divider.eq(~divider)
            m.d.comb += ClockSignal("half").eq(divider)
            m.d.half += self.ticks.eq(self.ticks + 1)
            return m

    class Source:
        design, params = "half_clock", None

        def cxxrtl(self):
            return generate_cxxrtl(HalfClock())

    with pytest.raises(BackendError, match=r"^half_clock clocks flip-flops from a signal of "):
        cxxrtl_build_plan(Source(), "plain")
    # FollowTarget clocks everything from its clk input: built as ever.
    assert cxxrtl_build_plan(DesignSource(FollowTargetParams()), "plain") is not None


@pytest.mark.parametrize("bit", [0, 1, 3])
def test_a_clock_from_one_bit_of_a_wider_register_is_refused_too(bit):
    # ClockSignal("slow") = divider[bit]: CXXRTL names the edge after the wire and the bit
    # (posedge_p_divider_1) and misses it as it misses a 1-bit divider's; the run would keep
    # the slow domain's counter at 0 on CXXRTL while pysim and Verilator count.
    from amaranth import ClockDomain, ClockSignal, Module, Signal
    from amaranth.lib import wiring
    from amaranth.lib.wiring import Out

    from fpga_robotics.hw.verilog import generate_cxxrtl
    from fpga_robotics.sim.backends.base import BackendError
    from fpga_robotics.sim.backends.cxxrtl_netlist import check_clocks

    class BitClock(wiring.Component):
        ticks: Out(8)

        def elaborate(self, platform):
            m = Module()
            m.domains.slow = ClockDomain(local=True)
            divider = Signal(4)
            m.d.sync += divider.eq(divider + 1)
            m.d.comb += ClockSignal("slow").eq(divider[bit])
            m.d.slow += self.ticks.eq(self.ticks + 1)
            return m

    with pytest.raises(BackendError, match=r"^bit_clock clocks flip-flops from a signal of its "):
        check_clocks(generate_cxxrtl(BitClock()), "bit_clock", "verilator")
