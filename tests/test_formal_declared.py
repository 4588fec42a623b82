"""Formal properties a design declares (``formal_properties``/``formal_covers``, docs/formal.md):
``fpga-robotics formal --design REF`` proves a true one and gives the counterexample of a
false one."""

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
