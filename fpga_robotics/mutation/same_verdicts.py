"""Two robot judges of the same mutants compared mutant by mutant (e.g. forked against
``--no-fork``): their ``robot.jsonl`` journals must give every mutant the same verdict."""

import json
import os

__all__ = ["VERDICT_FIELDS", "differing_verdicts", "journal_rows", "read_journal"]

#: What makes a robot verdict: caught or not, the first run that did not pass, how it did
#: not pass and which checks failed, and for a blind spot the run closest to failing.
VERDICT_FIELDS = ("caught", "run", "status", "failed_checks", "closest")


def journal_rows(path):
    """The verdict rows of the journal at ``path``, in order. A line that is not a whole row
    (the last one, torn by a kill while it was written) is left out: its mutant is not
    judged yet."""
    rows = []
    with open(path) as f:
        for line in f:
            try:
                row = json.loads(line)
            except ValueError:
                continue
            if isinstance(row, dict) and "index" in row:
                rows.append(row)
    return rows


def read_journal(out_dir):
    """``{mutant index: verdict row}`` of ``out_dir/robot.jsonl``."""
    return {int(row["index"]): row for row in journal_rows(os.path.join(out_dir, "robot.jsonl"))}


def differing_verdicts(a, b):
    """The mutant indices whose verdicts differ between journals ``a`` and ``b`` (as
    ``read_journal`` gives them), a mutant judged in one only included."""
    return sorted(
        k
        for k in a.keys() | b.keys()
        if k not in a
        or k not in b
        or [a[k].get(f) for f in VERDICT_FIELDS] != [b[k].get(f) for f in VERDICT_FIELDS]
    )
