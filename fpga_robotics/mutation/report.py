"""``report.html`` of a mutation run: the scores, the components, the robot-level blind spots
(module, signal, source line, what the mutant does, why no run shows it, the replay command
and recording of the closest-to-failing run) and the mutants no unit frame shows. One
self-contained file."""

import html
import os

from ..sim.files import write_atomic
from .reasons import blind_spot_reason
from .scores import blind_spots, by_module, robot_score, unit_score

__all__ = ["write_report"]

_STYLE = """body{font-family:sans-serif;margin:2em;max-width:80em}
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:.3em .6em;
text-align:left;vertical-align:top}th{background:#eee}code{font-size:90%}"""


def _pct(x):
    return "n/a" if x is None else f"{100 * x:.1f}%"


def _table(header, rows):
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _cone_note(verdict):
    """A verdict given by the mutant's fan-out cone: no run was made (the unmutated design's
    closest run stands for it)."""
    if verdict.get("judged_by") != "cone":
        return ""
    reached = ", ".join(verdict.get("cone_outputs") or ["no output"])
    return f"<br>no run made: its fan-out cone reaches only {html.escape(reached)}"


def write_report(
    out, campaign, mutants, unit_verdicts, robot_verdicts, baseline, recordings, width
):
    """Write ``out/report.html`` (``width``: the design's image width, for the blind spots'
    reasons); returns its path."""
    unit = {v.index: v.caught for v in unit_verdicts}
    robot = {k: v["caught"] for k, v in robot_verdicts.items()}
    us, rs = unit_score(unit), robot_score(unit, robot)
    effects = {v.index: v.effect() for v in unit_verdicts}
    blind = blind_spots(unit, robot)
    reasons = {v.index: blind_spot_reason(v, width) for v in unit_verdicts if v.index in blind}
    by_index = {m.index: m for m in mutants}
    e = html.escape
    parts = [
        (
            f"<!doctype html><meta charset=utf-8><title>Mutation coverage</title>"
            f"<style>{_STYLE}</style><h1>Mutation coverage of follow_target</h1>"
        ),
        (
            f"<p>{us['total']} mutants. Unit judge: {us['caught']} caught, {us['equivalent']} "
            f"equivalent on the unit frames (score {_pct(us['score'])}). Robot judge "
            f"(campaign <code>{e(campaign)}</code>, {len(baseline['passing'])} of "
            f"{len(baseline['runs'])} runs pass unmutated): {rs['caught']} of {rs['judged']} "
            f"unit-caught mutants caught (score {_pct(rs['score'])}).</p>"
        ),
        "<h2>By component</h2>",
        _table(
            ["component", "mutants", "unit judge caught", "robot judge caught"],
            [
                [e(name), r["total"], r["unit_caught"], r["robot_caught"]]
                for name, r in by_module(mutants, unit, robot).items()
            ],
        ),
    ]
    rows = []
    for k in sorted(blind, key=lambda i: (by_index[i].module, i)):
        m, v = by_index[k], robot_verdicts[k]
        rec = recordings.get(k)
        rows.append(
            [
                e(m.module or "top"),
                e(m.describe()),
                e(", ".join(m.sources)),
                e(effects[k]),
                e(reasons[k]),
                f"<code>{e(v.get('replay') or '')}</code>" + _cone_note(v),
                f'<a href="{e(rec)}">{e(rec)}</a>' if rec else "",
            ]
        )
    parts += [
        f"<h2>Blind spots: caught by the unit judge, missed by every run ({len(blind)})</h2>",
        _table(
            [
                "component",
                "mutant",
                "source",
                "what it does to the outputs",
                "why no run shows it",
                "closest-to-failing run",
                "recording",
            ],
            rows,
        ),
    ]
    caught_rows = []
    for k, v in sorted(robot_verdicts.items()):
        if v["caught"]:
            caught_rows.append(
                [
                    e(by_index[k].describe()),
                    e(v["status"]),
                    e(", ".join(v["failed_checks"]) or v.get("message") or ""),
                    f"<code>{e(v.get('replay') or '')}</code>",
                ]
            )
    parts += [
        f"<h2>Caught by the robot judge ({len(caught_rows)})</h2>",
        _table(["mutant", "status", "failed checks", "replay"], caught_rows),
    ]
    equivalent = [m for m in mutants if not unit.get(m.index)]
    parts += [
        f"<h2>Equivalent on the unit frames ({len(equivalent)})</h2>",
        _table(
            ["mutant", "source"], [[e(m.describe()), e(", ".join(m.sources))] for m in equivalent]
        ),
    ]
    path = os.path.join(out, "report.html")
    write_atomic(path, "\n".join(parts) + "\n", what="mutation report")
    return path
