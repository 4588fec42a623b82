"""Robot-judge journals compared mutant by mutant (fpga_robotics.mutation.same_verdicts)."""

import json

from fpga_robotics.mutation.same_verdicts import differing_verdicts, read_journal


def _journal(tmp_path, name, rows):
    d = tmp_path / name
    d.mkdir()
    (d / "robot.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows) + "\n")
    return str(d)


def _row(index, **kw):
    row = {"index": index, "caught": True, "run": 0, "status": "fail", "closest": None}
    row.update(failed_checks=["max_turn_law_violation_fraction"], wall_s=1.0 + index)
    row.update(kw)
    return row


def test_same_verdicts_with_other_times_and_order(tmp_path):
    a = _journal(tmp_path, "a", [_row(2), _row(5, caught=False, run=None, closest=3)])
    b = _journal(tmp_path, "b", [_row(5, caught=False, run=None, closest=3, wall_s=9.0), _row(2)])
    assert differing_verdicts(read_journal(a), read_journal(b)) == []


def test_each_verdict_field_and_a_missing_mutant_count(tmp_path):
    a = _journal(tmp_path, "a", [_row(k) for k in range(6)])
    b = _journal(
        tmp_path,
        "b",
        [
            _row(0),
            _row(1, run=1),
            _row(2, status="error"),
            _row(3, failed_checks=[]),
            _row(4, caught=False, closest=0),
        ],
    )
    assert differing_verdicts(read_journal(a), read_journal(b)) == [1, 2, 3, 4, 5]
