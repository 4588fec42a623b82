"""What a campaign found: a terminal summary and ``report.html`` (one self-contained file,
matplotlib figures embedded as PNG), both from the results rows alone."""

import base64
import html
import io
import json
from collections import defaultdict
from pathlib import Path

from ..sim.files import write_atomic
from .results import _cell

__all__ = ["failures_by_check", "format_report", "na_by_check", "write_html"]

#: Metric distributions shown: column, label.
METRICS = (
    ("min_distance_m", "closest distance to the target (m)"),
    ("found_fraction", "fraction of frames with the target found"),
    ("collisions_total", "collisions (person + wall + furniture)"),
)
#: Replay commands listed per failed check in the terminal summary.
SHOWN_PER_CHECK = 3


def _rate(rows):
    n = len(rows)
    return sum(r["status"] == "pass" for r in rows) / n if n else 0.0


def _value_key(v):
    """Numbers in order, then text, then runs without the key (an explicit set's rows on
    another set's axis)."""
    if v is None:
        return (2, 0, "")
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return (0, v, "")
    return (1, 0, str(v))


def _shown(v):
    """An axis value as the campaign file, the replay commands and results.csv write it
    (``true``, ``{"a": 1}``), not as Python prints it."""
    if v is None:
        return "(not set)"
    return v if isinstance(v, str) else json.dumps(v)


def _by(rows, column):
    groups = defaultdict(list)
    for r in rows:
        groups[r.get(column)].append(r)
    return dict(sorted(groups.items(), key=lambda kv: _value_key(kv[0])))


def _failed(row):
    return [n for n in (row.get("failed_checks") or "").split(";") if n]


def _names(entry):
    """The checks a known limit names (one, or a list)."""
    return [entry["check"]] if isinstance(entry["check"], str) else list(entry["check"])


def known_limit(row, name, known_limits):
    """The ``[[known_limits]]`` entry that explains the run's failed check ``name`` (its
    scenario and overrides match), else None."""
    for entry in known_limits:
        if name not in _names(entry):
            continue
        if entry.get("scenarios") and row.get("scenario") not in entry["scenarios"]:
            continue
        when = (entry.get("when") or {}).items()
        if all(row.get(k) == _cell(list(v) if isinstance(v, tuple) else v) for k, v in when):
            return entry
    return None


def explained(row, known_limits):
    """Whether the run failed and every check it failed is a known limit of the design."""
    failed = _failed(row)
    return (
        row["status"] == "fail"
        and bool(failed)
        and all(known_limit(row, n, known_limits) for n in failed)
    )


def campaign_passed(rows, known_limits=()):
    """Every run passed, or failed only where a known limit of the design explains it."""
    return bool(rows) and all(r["status"] == "pass" or explained(r, known_limits) for r in rows)


def known_limits_met(rows, known_limits):
    """``[(entry, rows), ...]``: each known limit with the failing runs it explains."""
    out = []
    for entry in known_limits:
        met = [
            r
            for r in rows
            if r["status"] == "fail"
            and any(known_limit(r, n, [entry]) is entry for n in _failed(r))
        ]
        out.append((entry, met))
    return out


def failures_by_check(rows, known_limits=()):
    """Failed check (or ``error``/``timeout``, or ``n/a`` for a run no check could judge) →
    the rows, most frequent first; a check a known limit explains for that run is left out."""
    groups = defaultdict(list)
    for r in rows:
        if r["status"] == "fail":
            for name in _failed(r):
                if known_limit(r, name, known_limits) is None:
                    groups[name].append(r)
        elif r["status"] in ("n/a", "error", "timeout"):
            groups[r["status"]].append(r)
    return dict(sorted(groups.items(), key=lambda kv: -len(kv[1])))


def _na_reasons(row):
    """``{check: reason}`` of the row's n/a checks (the reasons from ``checks_json``)."""
    names = [n for n in (row.get("na_checks") or "").split(";") if n]
    try:
        checks = json.loads(row.get("checks_json") or "[]")
    except ValueError:
        checks = []
    reasons = {
        c["name"]: c.get("reason") or c.get("text") or ""
        for c in checks
        if isinstance(c, dict) and c.get("passed") is None
    }
    return {n: reasons.get(n, "") for n in names}


def na_by_check(rows):
    """Check → ``[(row, reason), ...]`` of the runs it could not judge, most frequent first."""
    groups = defaultdict(list)
    for r in rows:
        for name, reason in _na_reasons(r).items():
            groups[name].append((r, reason))
    return dict(sorted(groups.items(), key=lambda kv: -len(kv[1])))


def _limit_text(entry):
    cond = ", ".join(f"{k}={_shown(v)}" for k, v in (entry.get("when") or {}).items())
    where = ", ".join(entry.get("scenarios") or [])
    scope = "; ".join(x for x in (cond, where) if x) or "every run"
    return f"{', '.join(_names(entry))} ({scope})"


def format_report(rows, axes, known_limits=(), missing=0):
    """The terminal summary (several lines). ``missing``: the campaign's runs that never ran
    (it was interrupted), which the first line counts."""
    counts = {
        s: sum(r["status"] == s for r in rows) for s in ("pass", "fail", "n/a", "error", "timeout")
    }
    runs = (
        f"{len(rows)} of {len(rows) + missing} runs (the campaign was interrupted; continue "
        f"it with --resume)"
        if missing
        else f"{len(rows)} runs"
    )
    lines = [
        f"{runs}: "
        + ", ".join(f"{n} {s}" for s, n in counts.items())
        + f" (pass rate {_rate(rows):.0%})"
    ]
    lines.append("pass rate per scenario:")
    for name, group in _by(rows, "scenario").items():
        lines.append(f"  {name:<20} {_rate(group):6.0%}  ({len(group)} runs)")
    for axis in axes:
        lines.append(f"pass rate per {axis}:")
        for value, group in _by(rows, axis).items():
            lines.append(f"  {_shown(value):<20} {_rate(group):6.0%}  ({len(group)} runs)")
    met = [(e, g) for e, g in known_limits_met(rows, known_limits) if g]
    if met:
        lines.append("known limits of the design (failures the campaign explains):")
        for entry, group in met:
            lines.append(f"  {_limit_text(entry)}: {len(group)} run(s): {entry['reason']}")
    groups = failures_by_check(rows, known_limits)
    if groups:
        lines.append("failures by check (replay one with its command):")
        for name, group in groups.items():
            lines.append(f"  {name}: {len(group)} run(s)")
            for r in group[:SHOWN_PER_CHECK]:
                lines.append(f"    {r['replay']}")
                if r["status"] in ("error", "timeout") and r.get("message"):
                    lines.append(f"      {r['message']}")
            if len(group) > SHOWN_PER_CHECK:
                lines.append(
                    f"    ... and {len(group) - SHOWN_PER_CHECK} more (report.html, results.csv)"
                )
    na = na_by_check(rows)
    if na:
        lines.append("checks that could not judge (n/a; not counted as pass or fail):")
        for name, group in na.items():
            reasons = sorted({reason for _, reason in group})
            lines.append(
                f"  {name}: {len(group)} run(s): {reasons[0]}"
                + (f" (and {len(reasons) - 1} other reason(s))" if len(reasons) > 1 else "")
            )
    return "\n".join(lines)


def _png(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    import matplotlib.pyplot as plt  # lazy: pyplot costs ~1.5 s; only plots need it

    plt.close(fig)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode()


def _bar_figure(groups, title, xlabel):
    import matplotlib.pyplot as plt  # lazy: pyplot costs ~1.5 s; only plots need it

    labels = [_shown(k) for k in groups]
    fig, ax = plt.subplots(figsize=(max(4, 0.6 * len(labels) + 2), 3))
    ax.bar(labels, [100 * _rate(g) for g in groups.values()], color="#4a7")
    ax.set_ylim(0, 100)
    ax.set_ylabel("pass rate (%)")
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    if len(labels) > 4:
        ax.tick_params(axis="x", rotation=45)
    return _png(fig)


def _heatmap(rows, x_axis, y_axis, label):
    import matplotlib.pyplot as plt  # lazy: pyplot costs ~1.5 s; only plots need it
    import numpy as np  # lazy: ~0.2 s; only plots need it

    xs = [x for x in _by(rows, x_axis) if x is not None]
    ys = [y for y in _by(rows, y_axis) if y is not None]
    grid = np.full((len(ys), len(xs)), np.nan)
    for j, y in enumerate(ys):
        for i, x in enumerate(xs):
            group = [r for r in rows if r.get(x_axis) == x and r.get(y_axis) == y]
            if group:
                grid[j, i] = 100 * _rate(group)
    fig, ax = plt.subplots(figsize=(1 + 0.8 * len(xs) + 1.5, 1 + 0.5 * len(ys)))
    im = ax.imshow(grid, origin="lower", cmap="RdYlGn", vmin=0, vmax=100, aspect="auto")
    ax.set_xticks(range(len(xs)), [str(x) for x in xs])
    ax.set_yticks(range(len(ys)), [str(y) for y in ys])
    ax.set_xlabel(x_axis)
    ax.set_ylabel(y_axis)
    for j in range(len(ys)):
        for i in range(len(xs)):
            if not np.isnan(grid[j, i]):
                v = grid[j, i]  # white on the dark ends of the colour map
                ax.text(
                    i,
                    j,
                    f"{v:.0f}",
                    ha="center",
                    va="center",
                    fontsize=9,
                    color="white" if v < 25 or v > 75 else "black",
                )
    fig.colorbar(im, ax=ax, label="pass rate (%)")
    ax.set_title(f"{label}: pass rate (%)")
    return _png(fig)


def _histogram(rows, column, label):
    import matplotlib.pyplot as plt  # lazy: pyplot costs ~1.5 s; only plots need it
    import numpy as np  # lazy: ~0.2 s; only plots need it

    fig, ax = plt.subplots(figsize=(4.5, 3))
    every = [r[column] for r in rows if isinstance(r.get(column), (int, float))]
    bins = np.histogram_bin_edges(every, bins=20)  # the same bins for passes and failures
    for status, color in (("pass", "#4a7"), ("fail", "#c44")):
        values = [
            r[column]
            for r in rows
            if r["status"] == status and isinstance(r.get(column), (int, float))
        ]
        if values:
            ax.hist(values, bins=bins, alpha=0.6, color=color, label=f"{status} ({len(values)})")
    ax.set_xlabel(label)
    ax.set_ylabel("runs")
    ax.legend()
    return _png(fig)


def _with_totals(rows):
    out = []
    for r in rows:
        r = dict(r)
        kinds = [k for k in r if k.startswith("collisions_") and k != "collisions_total"]
        if kinds:
            r["collisions_total"] = sum(r[k] or 0 for k in kinds)
        out.append(r)
    return out


def _recording(row):
    """A link to the run's recording, if the campaign kept one."""
    rec = row.get("recording") or ""
    return f"<a href='{html.escape(rec)}'>{html.escape(Path(rec).name)}</a>" if rec else ""


def write_html(path, rows, axes, meta):
    """``report.html``: pass rates, the heatmap of the first two axes (of the runs that set
    both), metric distributions, the failing runs grouped by check, each with its replay
    command, and the checks that could not judge some runs (n/a), with their reasons. ``meta``: the campaign's
    ``campaign.json`` (``missing``: how many of its runs never ran)."""
    import matplotlib  # lazy: pyplot costs ~1.5 s; only plots need it

    matplotlib.use("Agg")
    rows = _with_totals(rows)
    esc = html.escape
    title = f"Campaign {meta.get('name', '')}"
    parts = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{esc(title)}</title>",
        (
            "<style>body{font-family:sans-serif;margin:2em;max-width:70em}"
            "code{background:#eee;padding:0 .2em;word-break:break-all}"
            "td,th{padding:.2em .6em;text-align:left}img{margin:.5em}</style></head><body>"
        ),
        f"<h1>{esc(title)}</h1>",
    ]
    if meta.get("description"):
        parts.append(f"<p>{esc(meta['description'])}</p>")
    known_limits = meta.get("known_limits") or ()
    summary = format_report(rows, axes, known_limits, meta.get("missing", 0)).splitlines()[0]
    parts.append(f"<p><b>{esc(summary)}</b></p>")
    facts = [
        (k, meta[k])
        for k in ("backend", "workers", "scheduler", "wall_s", "build_s", "version")
        if meta.get(k) is not None
    ]
    if facts:
        parts.append(
            "<table>"
            + "".join(f"<tr><th>{esc(k)}</th><td>{esc(str(v))}</td></tr>" for k, v in facts)
            + "</table>"
        )
    if rows:
        parts.append("<h2>Pass rate</h2>")
        parts.append(
            f"<img src='{_bar_figure(_by(rows, 'scenario'), 'per scenario', 'scenario')}'>"
        )
        for axis in axes:
            parts.append(f"<img src='{_bar_figure(_by(rows, axis), f'per {axis}', axis)}'>")
        # One map per scenario (each has its own conditions), of the runs that set both
        # keys: [[sets]] tables that each vary one key would give empty maps.
        maps = {}
        if len(axes) >= 2:
            for name, group in _by(rows, "scenario").items():
                both = [r for r in group if None not in (r.get(axes[0]), r.get(axes[1]))]
                if both:
                    maps[name] = both
        if maps:
            parts.append(f"<h2>{esc(axes[0])} x {esc(axes[1])}</h2>")
            for name, group in maps.items():
                parts.append(f"<img src='{_heatmap(group, axes[0], axes[1], name)}'>")
        parts.append("<h2>Metric distributions</h2>")
        for column, label in METRICS:
            if any(isinstance(r.get(column), (int, float)) for r in rows):
                parts.append(f"<img src='{_histogram(rows, column, label)}'>")
    if known_limits:
        parts.append("<h2>Known limits of the design</h2>")
        parts.append(
            "<p>Failures the campaign expects: a limit of the design under that "
            "variation, with the reason. They are not counted against it.</p>"
        )
        for entry, group in known_limits_met(rows, known_limits):
            parts.append(
                f"<h3>{esc(_limit_text(entry))}: {len(group)} run(s)</h3>"
                f"<p>{esc(entry['reason'])}</p>"
            )
            if group:
                parts.append(
                    "<table><tr><th>scenario</th><th>seed</th><th>replay</th>"
                    "<th>recording</th></tr>"
                )
                for r in group:
                    parts.append(
                        f"<tr><td>{esc(str(r['scenario']))}</td><td>{r['seed']}</td>"
                        f"<td><code>{esc(r['replay'])}</code></td><td>{_recording(r)}</td></tr>"
                    )
                parts.append("</table>")
    groups = failures_by_check(rows, known_limits)
    parts.append("<h2>Failing runs by check</h2>")
    if not groups:
        parts.append(
            "<p>None: every run passed"
            + (" or failed only by a known limit.</p>" if known_limits else ".</p>")
        )
    for name, group in groups.items():
        parts.append(f"<h3>{esc(name)} ({len(group)} run(s))</h3><table>")
        parts.append(
            "<tr><th>scenario</th><th>seed</th><th>what</th><th>replay</th><th>recording</th></tr>"
        )
        for r in group:
            parts.append(
                f"<tr><td>{esc(str(r['scenario']))}</td><td>{r['seed']}</td>"
                f"<td>{esc(r.get('message') or '')}</td>"
                f"<td><code>{esc(r['replay'])}</code></td><td>{_recording(r)}</td></tr>"
            )
        parts.append("</table>")
    na = na_by_check(rows)
    if na:
        parts.append("<h2>Checks that could not judge (n/a)</h2>")
        parts.append(
            "<p>Neither a pass nor a failure: the run gave the check nothing to judge. "
            "A run whose every check is n/a has the status n/a.</p>"
        )
    for name, group in na.items():
        parts.append(f"<h3>{esc(name)} ({len(group)} run(s))</h3><table>")
        parts.append(
            "<tr><th>scenario</th><th>seed</th><th>status</th><th>reason</th><th>replay</th></tr>"
        )
        for r, reason in group:
            parts.append(
                f"<tr><td>{esc(str(r['scenario']))}</td><td>{r['seed']}</td>"
                f"<td>{esc(r['status'])}</td><td>{esc(reason)}</td>"
                f"<td><code>{esc(r['replay'])}</code></td></tr>"
            )
        parts.append("</table>")
    parts.append("</body></html>")
    write_atomic(path, "\n".join(parts), what="report")
