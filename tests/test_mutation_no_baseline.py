"""A campaign none of whose runs passes with the unmutated design cannot judge a mutant:
``mutate`` says why each run did not pass, judges no mutant (no verdict of "passed every
run" from no run at all) and exits with 1."""

import json

import pytest
from bump_mutate import DATA, mutate_bump_stop


@pytest.mark.slow  # a Verilator build of the mutant netlist, a Dask worker
def test_no_passing_run_judges_no_mutant_and_says_why(tmp_path, capsys):
    campaign = tmp_path / "strict.toml"
    # bump_stop drives at 300 DPS: a limit of 100 fails its own run.
    campaign.write_text(
        f'scenarios = ["{DATA / "bump_wall.toml"}"]\nseeds = "0"\nduration = 2.0\n'
        'set = ["checks.max_wheel_command_dps=100"]\n'
    )
    out = tmp_path / "m"
    code, text, _ = mutate_bump_stop(
        out, capsys, "--mutants", "4", "--campaign", str(campaign), "--workers", "1"
    )
    assert code == 1
    assert "no run passes with the unmutated design" in text
    assert "bump_wall.toml: fail: failed checks: max_wheel_command_dps" in text
    assert "0 of 1 runs pass unmutated): no mutant judged" in text and "0 of 0" not in text
    assert "robot judge" not in "".join(  # no module's robot score from no run
        line for line in text.splitlines() if line.startswith("  ") and " caught" in line
    )
    result = json.loads((out / "mutants.json").read_text())
    assert result["baseline"]["passing"] == [] and result["baseline"]["statuses"] == ["fail"]
    assert all(m["robot"] is None for m in result["mutants"])
    assert result["robot"]["judged"] == 0
    assert not (out / "robot.jsonl").exists() or not (out / "robot.jsonl").read_text().strip()


@pytest.mark.slow  # a Verilator build of the mutant netlist, a Dask worker
def test_a_rerun_leaves_no_report_of_the_run_before(tmp_path, capsys):
    """Rerun into the same folder, the robot judge's report.html, recordings and journal of
    the run before are gone where this run writes none of its own."""
    passing, strict = tmp_path / "passing.toml", tmp_path / "strict.toml"
    scenario = f'scenarios = ["{DATA / "bump_wall.toml"}"]\nseeds = "0"\nduration = 2.0\n'
    passing.write_text(scenario)
    strict.write_text(scenario + 'set = ["checks.max_wheel_command_dps=100"]\n')
    out = tmp_path / "m"
    judged = ("--mutants", "4", "--workers", "1", "--recordings", "1")
    code, text, _ = mutate_bump_stop(out, capsys, *judged, "--campaign", str(passing))
    assert code == 0 and "blind spots:" in text  # a blind spot: its closest run recorded
    assert {p.name for p in out.iterdir()} >= {"report.html", "recordings", "robot.jsonl"}
    code, text, _ = mutate_bump_stop(out, capsys, *judged, "--campaign", str(strict))
    assert code == 1 and "no run passes with the unmutated design" in text
    assert not (out / "report.html").exists() and not (out / "recordings").exists()
    code, _, _ = mutate_bump_stop(out, capsys, "--mutants", "4")
    assert code == 0 and json.loads((out / "mutants.json").read_text())["campaign"] is None
    assert not (out / "robot.jsonl").exists()
