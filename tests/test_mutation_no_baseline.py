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
    assert "0 of 0 unit-caught mutants caught: score n/a; no mutant judged" in text
    assert "robot judge" not in "".join(  # no module's robot score from no run
        line for line in text.splitlines() if line.startswith("  ") and " caught" in line
    )
    result = json.loads((out / "mutants.json").read_text())
    assert result["baseline"]["passing"] == [] and result["baseline"]["statuses"] == ["fail"]
    assert all(m["robot"] is None for m in result["mutants"])
    assert result["robot"]["judged"] == 0
    assert not (out / "robot.jsonl").exists() or not (out / "robot.jsonl").read_text().strip()
