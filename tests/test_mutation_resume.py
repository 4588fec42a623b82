"""``mutate --resume``: the robot judge keeps the verdicts already in its journal, but only of
the very same mutants judged by the very same campaign runs; a journal of other mutants
(another seed) or of other runs (the campaign's duration edited) is refused before anything
in the output folder is touched; and only of the mutants the unit judge catches this time."""

import json

import pytest
from bump_mutate import DATA, mutate_bump_stop

SAME = ("caught", "run", "status", "failed_checks", "closest")


def _mutate(out, seed, capsys, *more, duration=3.0):
    code, _, err = _mutate_printing(out, seed, capsys, *more, duration=duration)
    return code, err


def _mutate_printing(out, seed, capsys, *more, duration=3.0):
    campaign = out.parent / "bump.toml"
    campaign.write_text(
        f'scenarios = ["{DATA / "bump_wall.toml"}"]\nseeds = "0"\nduration = {duration}\n'
    )
    return mutate_bump_stop(
        out,
        capsys,
        *("--mutants", "6", "--seed", str(seed), "--campaign", str(campaign)),
        *("--workers", "1", "--recordings", "0", *more),
    )


def _rows(out):
    lines = (out / "robot.jsonl").read_text().splitlines()
    return {r["index"]: r for r in map(json.loads, filter(None, lines))}


@pytest.mark.slow  # Verilator builds of the mutant netlist, a Dask worker
def test_resume_keeps_only_verdicts_of_the_same_mutants(tmp_path, capsys):
    out = tmp_path / "m"
    code, err = _mutate(out, 1, capsys)
    assert code == 0, err
    first = _rows(out)
    assert len(first) >= 2 and len({r["mutants"] for r in first.values()}) == 1
    # Killed while writing its third verdict (the line torn): resumed, the others are judged,
    # and all are as before.
    journal = out / "robot.jsonl"
    lines = journal.read_text().splitlines()
    journal.write_text("".join(line + "\n" for line in lines[:2]) + lines[2][: len(lines[2]) // 2])
    code, err = _mutate(out, 1, capsys, "--resume")
    assert code == 0, err
    again = _rows(out)
    assert {k: {f: r[f] for f in SAME} for k, r in again.items()} == {
        k: {f: r[f] for f in SAME} for k, r in first.items()
    }
    # Seed 2's mutants 1..6 are other faults: the journal is refused, nothing rewritten.
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    code, err = _mutate(out, 2, capsys, "--resume")
    assert code == 2
    assert "--resume:" in err and "holds verdicts of other mutants" in err
    assert "Traceback" not in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    # The same mutants, the campaign's runs made 2 s: their verdicts are not these runs'.
    code, err = _mutate(out, 1, capsys, "--resume", duration=2.0)
    assert code == 2 and err.count("\n") == 1
    assert "holds verdicts judged by other runs than campaign bump's" in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    # Resumed on 3 unit cycles, the unit judge catches fewer of them: only those have robot
    # verdicts, in the scores, the lists and the journal alike.
    code, err = _mutate(out, 1, capsys, "--resume", "--cycles", "3")
    assert code == 0, err
    result = json.loads((out / "mutants.json").read_text())
    unit_caught = {m["index"] for m in result["mutants"] if m["unit"]["caught"]}
    assert unit_caught < set(first)
    assert {m["index"] for m in result["mutants"] if m["robot"]} == unit_caught
    assert result["robot"]["judged"] == len(unit_caught)
    assert {k: {f: r[f] for f in SAME} for k, r in _rows(out).items()} == {
        k: {f: r[f] for f in SAME} for k, r in first.items() if k in unit_caught
    }


def test_a_torn_last_line_of_the_journal_is_not_a_verdict(tmp_path):
    """A row cut short by a kill is left out (its mutant is judged again), the rows before
    it are kept."""
    from fpga_robotics.mutation.same_verdicts import journal_rows, read_journal

    rows = [{"index": 3, "caught": True}, {"index": 5, "caught": False}]
    text = "".join(json.dumps(r) + "\n" for r in rows)
    (tmp_path / "robot.jsonl").write_text(text + json.dumps({"index": 7, "caught": True})[:12])
    assert journal_rows(tmp_path / "robot.jsonl") == rows
    assert read_journal(tmp_path) == {3: rows[0], 5: rows[1]}


@pytest.mark.slow  # Verilator builds of the mutant netlist, a Dask worker
def test_a_resumed_run_in_full_prints_no_forked_runs_of_the_verdicts_it_kept(tmp_path, capsys):
    # Forked first; two verdicts kept, the others judged again in full (--no-fork): the
    # forked runs of the kept ones are not this run's, so no line counts them.
    out = tmp_path / "m"
    code, printed, err = _mutate_printing(out, 1, capsys)
    assert code == 0, err
    assert "forked runs:" in printed
    rows = _rows(out)
    assert len(rows) >= 3 and any(r.get("forks") for r in rows.values())
    kept = sorted(rows)[:2]
    (out / "robot.jsonl").write_text("".join(json.dumps(rows[k]) + "\n" for k in kept))
    code, printed, err = _mutate_printing(out, 1, capsys, "--resume", "--no-fork")
    assert code == 0, err
    assert "forked runs:" not in printed and "settled by their fan-out cone" not in printed
    result = json.loads((out / "mutants.json").read_text())
    assert result["baseline"]["kept"] == kept
    assert result["baseline"]["judged_here"] == len(rows) - 2
