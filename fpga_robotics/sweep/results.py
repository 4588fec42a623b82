"""The results of a campaign: one row per run, written as the runs arrive.

Every row is appended to ``results.jsonl`` at once (one line, flushed: an interrupted campaign
keeps every finished run; a torn last line is ignored on reading). ``results.parquet`` and
``results.csv`` are rewritten from all rows every few seconds and at the end, each atomically
(a reader sees the previous complete table or the new one, never half of one).
``campaign.json`` says what the campaign was (name, grid axes, build times).
"""

import csv
import io
import json
import re
import shutil
import time
from pathlib import Path

from ..hw.errors import UsageError
from ..sim.files import atomic_path, write_atomic, write_json_atomic

__all__ = ["STATUSES", "ResultStore", "load_rows", "make_row", "read_meta"]

#: A run's status: its verdict ("n/a": checks were set and none could judge it), or why it has
#: none.
STATUSES = ("pass", "fail", "n/a", "error", "timeout")
#: Statuses of finished runs that ``--resume`` does not run again (an error or a timeout may
#: have been the machine's: those are run again).
DONE = ("pass", "fail", "n/a")

JOURNAL = "results.jsonl"
PARQUET = "results.parquet"
CSV = "results.csv"
META = "campaign.json"

#: Columns every row has, first in the tables.
LEAD = (
    "run_id",
    "scenario",
    "seed",
    "status",
    "message",
    "failed_checks",
    "na_checks",
    "wall_s",
    "cpu_s",
    "run_s",
    "replay",
    "recording",
)


def _cell(value):
    """A table cell: scalars as they are, lists and tables as JSON text."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return json.dumps(value, sort_keys=True)


def make_row(spec, run_id, scenario_name, outcome):
    """The results row of a run: identity, overrides (one column each), status, times, the
    replay command, and every summary field (collisions and checks one column each:
    ``check_<name>`` True, False or None for n/a). ``failed_checks`` names the checks that
    failed, ``na_checks`` those that could not judge the run (their reasons are in
    ``checks_json``)."""
    row = {
        "run_id": run_id,
        "scenario": scenario_name,
        "seed": spec.seed,
        "status": outcome["status"],
        "message": outcome.get("message", ""),
        "failed_checks": "",
        "na_checks": "",
        "wall_s": round(outcome.get("wall_s", 0.0), 4),
        "cpu_s": round(outcome.get("cpu_s", 0.0), 4),
        "run_s": round(outcome.get("run_s", 0.0), 4),
        "replay": spec.replay(),
        "recording": "",
        "scenario_arg": spec.scenario,
    }
    for key, value in spec.overrides:
        row[key] = _cell(value)
    summary = outcome.get("summary")
    if summary:
        for key, value in summary.items():
            if key in ("scenario", "seed"):
                continue
            if key == "collisions":
                for kind, n in value.items():
                    row[f"collisions_{kind}"] = n
            elif key == "checks":
                for check in value:
                    row[f"check_{check['name']}"] = check["passed"]
                failed = [c for c in value if c["passed"] is False]
                na = [c for c in value if c["passed"] is None]
                row["failed_checks"] = ";".join(c["name"] for c in failed)
                row["na_checks"] = ";".join(c["name"] for c in na)
                shown = failed if failed else na if outcome["status"] == "n/a" else []
                if shown and not row["message"]:
                    row["message"] = "; ".join(f"{c['name']}: {c['text']}" for c in shown)
                row["checks_json"] = json.dumps(value)
            elif key == "overrides":
                row["overrides"] = " ".join(value)
            else:
                row[key] = _cell(value)
    return row


def _column_type(values):
    import pyarrow as pa  # lazy: ~0.3 s the workers need not pay

    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pa.bool_()
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return pa.int64()
    if present and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
        return pa.float64()
    return pa.string()


def _columns(rows):
    names = list(LEAD)
    for row in rows:
        for key in row:
            if key not in names:
                names.append(key)
    return names


def _table(rows):
    import pyarrow as pa  # lazy: ~0.3 s the workers need not pay

    names = _columns(rows)
    arrays = {}
    for name in names:
        values = [row.get(name) for row in rows]
        kind = _column_type(values)
        if kind == pa.string():
            values = [
                None if v is None else (v if isinstance(v, str) else json.dumps(v)) for v in values
            ]
        elif kind == pa.float64():
            values = [None if v is None else float(v) for v in values]
        arrays[name] = pa.array(values, type=kind)
    return pa.table(arrays)


class ResultStore:
    """The results folder of a campaign. ``resume``: keep the rows already there that are
    finished runs of the campaign: ``run_ids``, the identities of its runs (None: every
    finished run); without it none is kept. ``dropped``: how many rows already there were
    not kept."""

    FLUSH_EVERY_S = 2.0

    def __init__(self, out_dir, *, resume=False, run_ids=None):
        self.dir = Path(out_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        rows = load_rows(self.dir)
        # Runs to do again (errors, timeouts) are dropped from the journal too, and so are
        # rows of runs the campaign no longer makes (a scenario or design file edited, an
        # option or the package version changed: the identity differs), and every row
        # without resume, each with its recording and bag: no file is left that no row names.
        self._rows = {
            r["run_id"]: r
            for r in rows
            if resume and r.get("status") in DONE and (run_ids is None or r["run_id"] in run_ids)
        }
        stale = [r["run_id"] for r in rows if r["run_id"] not in self._rows]
        self.dropped = len(stale)
        self._rewrite_journal()
        for run_id in stale:
            self._remove_files_of(run_id)
        self._journal = open(self.dir / JOURNAL, "a")  # noqa: SIM115 (open for the campaign)
        self._last_flush = time.monotonic()
        self._dirty = True

    def _rewrite_journal(self):
        text = "".join(json.dumps(r) + "\n" for r in self.rows)
        write_atomic(self.dir / JOURNAL, text, what="results journal")

    def _remove_files_of(self, run_id):
        """A dropped run's recording and bag (``recordings/<id>.rrd``, ``bags/<id>/``)."""
        if not re.fullmatch(r"[0-9a-f]+", str(run_id)):  # a hand-edited row: not a file name
            return
        (self.dir / "recordings" / f"{run_id}.rrd").unlink(missing_ok=True)
        shutil.rmtree(self.dir / "bags" / run_id, ignore_errors=True)

    @property
    def rows(self):
        return list(self._rows.values())

    def done_ids(self):
        return set(self._rows)

    def add(self, row):
        """Record a finished run (again: a later row of the same run replaces it)."""
        self._rows[row["run_id"]] = row
        self._journal.write(json.dumps(row) + "\n")
        self._journal.flush()
        self._dirty = True
        if time.monotonic() - self._last_flush >= self.FLUSH_EVERY_S:
            self.flush()

    def flush(self):
        """Rewrite the Parquet and CSV tables from every row, each atomically."""
        if not self._dirty:
            return
        write_tables(self.dir, self.rows)
        self._dirty = False
        self._last_flush = time.monotonic()

    def close(self):
        self.flush()
        self._journal.close()


def write_tables(out_dir, rows):
    import pyarrow.parquet as pq  # lazy: ~0.3 s the workers need not pay

    out_dir = Path(out_dir)
    table = _table(rows)
    with atomic_path(out_dir / PARQUET, what="results table") as tmp:
        pq.write_table(table, tmp)
    names = table.column_names
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=names, extrasaction="ignore")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _csv_cell(row.get(k)) for k in names})
    write_atomic(out_dir / CSV, buf.getvalue(), what="results table")


def _csv_cell(v):
    if v is None:
        return ""
    return v if isinstance(v, str) else json.dumps(v)


def load_rows(out_dir):
    """The rows in ``out_dir``: the journal (every finished run), else the Parquet table."""
    out_dir = Path(out_dir)
    journal = out_dir / JOURNAL
    rows = []
    if journal.is_file():
        for line in journal.read_text().splitlines():
            try:
                row = json.loads(line)
            except ValueError:  # a line torn by a crash: that run is not finished
                continue
            if isinstance(row, dict) and "run_id" in row:
                rows.append(row)
        # A run finished twice (a resumed error run): the last row counts.
        return list({r["run_id"]: r for r in rows}.values())
    parquet = out_dir / PARQUET
    if parquet.is_file():
        import pyarrow as pa  # lazy: ~0.3 s the workers need not pay
        import pyarrow.parquet as pq  # lazy: as above

        try:
            return pq.read_table(parquet).to_pylist()
        except (pa.ArrowException, OSError) as exc:  # truncated, or not a table we wrote
            raise UsageError(
                f"{parquet} is not a readable results table ({exc}); run the campaign "
                "again, or remove the file"
            ) from None
    return []


def write_meta(out_dir, meta):
    write_json_atomic(Path(out_dir) / META, meta, what="campaign description")


def read_meta(out_dir):
    try:
        return json.loads((Path(out_dir) / META).read_text())
    except (OSError, ValueError):
        return {}
