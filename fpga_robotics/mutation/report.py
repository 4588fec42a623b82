"""``report.html`` of a mutation run: the scores, the components, the robot-level blind spots
(module, signal, source line, what the mutant does, why no run shows it where a reason is
known, the replay command and recording of the closest-to-failing run) and the mutants the
unit judge does not catch. One self-contained file."""

import html
import os

from ..sim.files import write_atomic

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


def write_report(out, results, recordings, *, title, inputs):
    """Write ``out/report.html`` from ``results`` (``mutants.json``'s content: its scores,
    campaign, baseline, modules and mutants with their verdicts); ``recordings``: ``{index:
    path}`` of the recorded closest runs; ``title``: the design; ``inputs``: what the unit
    judge ran the mutants on ("the unit frames"). Returns its path."""
    us, rs, baseline = results["unit"], results["robot"], results["baseline"]
    rows = results["mutants"]
    blind = [m for m in rows if m["robot"] is not None and not m["robot"]["caught"]]
    # Every blind spot has a reason (reasons.py) but those judged before reasons existed.
    with_reason = any(m.get("blind_spot_reason") for m in blind)
    e = html.escape
    parts = [
        (
            f"<!doctype html><meta charset=utf-8><title>Mutation coverage</title>"
            f"<style>{_STYLE}</style><h1>Mutation coverage of {e(title)}</h1>"
        ),
        (
            f"<p>{us['total']} mutants. Unit judge: {us['caught']} caught, {us['equivalent']} "
            f"equivalent on {e(inputs)} (score {_pct(us['score'])}). Robot judge "
            f"(campaign <code>{e(results['campaign'])}</code>, {len(baseline['passing'])} of "
            f"{len(baseline['runs'])} runs pass unmutated): {rs['caught']} of {rs['judged']} "
            f"unit-caught mutants caught (score {_pct(rs['score'])}).</p>"
        ),
        "<h2>By component</h2>",
        _table(
            ["component", "mutants", "unit judge caught", "robot judge caught"],
            [
                [e(name), r["total"], r["unit_caught"], r["robot_caught"]]
                for name, r in results["modules"].items()
            ],
        ),
    ]
    blind_rows = []
    for m in sorted(blind, key=lambda m: (m["module"], m["index"])):
        v, rec = m["robot"], recordings.get(m["index"])
        blind_rows.append(
            [
                e(m["module"] or "top"),
                e(m["describe"]),
                e(", ".join(m["sources"])),
                e(m["unit"]["effect"]),
                *([e(m.get("blind_spot_reason") or "")] if with_reason else []),
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
                *(["why no run shows it"] if with_reason else []),
                "closest-to-failing run",
                "recording",
            ],
            blind_rows,
        ),
    ]
    caught_rows = [
        [
            e(m["describe"]),
            e(m["robot"]["status"]),
            e(", ".join(m["robot"]["failed_checks"]) or m["robot"].get("message") or ""),
            f"<code>{e(m['robot'].get('replay') or '')}</code>",
        ]
        for m in rows
        if m["robot"] is not None and m["robot"]["caught"]
    ]
    parts += [
        f"<h2>Caught by the robot judge ({len(caught_rows)})</h2>",
        _table(["mutant", "status", "failed checks", "replay"], caught_rows),
    ]
    equivalent = [m for m in rows if not m["unit"]["caught"]]
    parts += [
        f"<h2>Equivalent on {e(inputs)} ({len(equivalent)})</h2>",
        _table(
            ["mutant", "source"],
            [[e(m["describe"]), e(", ".join(m["sources"]))] for m in equivalent],
        ),
    ]
    path = os.path.join(out, "report.html")
    write_atomic(path, "\n".join(parts) + "\n", what="mutation report")
    return path
