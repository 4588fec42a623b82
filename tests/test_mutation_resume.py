"""``mutate --resume``: the robot judge keeps the verdicts already in its journal, but only of
the very same mutants judged by the very same campaign runs; a journal of other mutants
(another seed) or of other runs (the campaign's duration edited) is refused before anything
in the output folder is touched."""

import json

import pytest
from bump_mutate import DATA, mutate_bump_stop

SAME = ("caught", "run", "status", "failed_checks", "closest")


def _mutate(out, seed, capsys, *more, duration=3.0):
    campaign = out.parent / "bump.toml"
    campaign.write_text(
        f'scenarios = ["{DATA / "bump_wall.toml"}"]\nseeds = "0"\nduration = {duration}\n'
    )
    code, _, err = mutate_bump_stop(
        out,
        capsys,
        *("--mutants", "6", "--seed", str(seed), "--campaign", str(campaign)),
        *("--workers", "1", "--recordings", "0", *more),
    )
    return code, err


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
    # Interrupted after two verdicts: resumed, the others are judged, and all are as before.
    journal = out / "robot.jsonl"
    journal.write_text("".join(line + "\n" for line in journal.read_text().splitlines()[:2]))
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
