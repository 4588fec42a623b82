"""``fpga-robotics sweep CAMPAIGN [options]``, ``... report DIR`` and ``... --bench``.

Exit status: 0 when every run passed, 1 when some did not, 2 for a usage error (bad option,
malformed campaign file, unknown scenario or key, bad override value, unreachable scheduler).
``report DIR`` exits as the campaign did (1 also when runs are missing), or 0 with --exit-zero.
"""

import argparse
import math
import sys
from pathlib import Path

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.sim.files import check_output_dir
from fpga_robotics.sweep.api import dir_passed, report_dir, run_campaign
from fpga_robotics.sweep.campaign import (
    load_campaign,
    parse_seeds,
    read_campaign_file,
    shipped_campaigns,
)
from fpga_robotics.sweep.engine import RECORD_LOG_EVERY, check_cluster_options
from fpga_robotics.sweep.plan import make_plan
from fpga_robotics.sweep.report import campaign_passed, format_report
from fpga_robotics.sweep.results import load_rows

__all__ = ["build_parser", "main"]

PROG = "fpga-robotics sweep"
RECORD = ("failing", "all", "none")


def build_parser(prog=PROG):
    p = CommandParser(
        prog=prog,
        usage=f"%(prog)s [CAMPAIGN] [options]\n       {prog} report DIR",
        description="Run a verification campaign (scenarios x seeds x a grid of overrides) on "
        "Dask and report where the design fails. `report DIR` rebuilds a report.",
        epilog=f"shipped campaigns: {', '.join(shipped_campaigns())}",
    )
    p.add_argument(
        "campaign",
        nargs="?",
        metavar="CAMPAIGN",
        help="a shipped campaign name or a .toml file (docs/campaigns.md)",
    )
    g = p.add_argument_group("what runs (each overrides the campaign file)")
    g.add_argument("--scenarios", metavar="A,B", help="scenarios, comma-separated")
    g.add_argument("--seeds", metavar="A-B|A,B,C", help="seeds: a range or a list")
    g.add_argument("--backend", metavar="NAME", help="design simulator, as run --backend")
    g.add_argument("--resolution", metavar="WxH", help="as run --resolution")
    g.add_argument("--duration", type=float, metavar="S", help="as run --duration")
    g.add_argument(
        "--set",
        dest="fixed",
        action="append",
        default=None,
        metavar="KEY=VALUE",
        help="an override for every run, as run --set (repeatable)",
    )
    g.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="KEY=[V1,V2]",
        help="a grid axis: a TOML list of values (repeatable; replaces the file's "
        "axis of that key)",
    )
    g.add_argument("--shadow", metavar="SPEC", help="as run --shadow (e.g. published)")
    g.add_argument("--design", metavar="REF", help="as run --design")
    g.add_argument("--ports", metavar="PORTS.toml", help="as run --ports")
    g.add_argument(
        "--timeout",
        type=float,
        metavar="S",
        help="per-run timeout (default: the campaign file's timeout, else 10x the run's "
        "expected time, at least 30 s)",
    )
    g.add_argument("--max-runs", type=int, metavar="N", help="only the first N runs")
    e = p.add_argument_group("where and how")
    e.add_argument(
        "--workers",
        type=int,
        metavar="N",
        help="embedded cluster: N worker processes (1..256), one thread each (default: the "
        "machine's cores)",
    )
    e.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="use an existing Dask scheduler (tcp://HOST:8786) instead",
    )
    e.add_argument("--out", metavar="DIR", help="results folder (default runs/sweeps/NAME)")
    e.add_argument(
        "--resume",
        action="store_true",
        help="keep the runs already in --out and run only the others",
    )
    e.add_argument(
        "--record",
        choices=RECORD,
        default="failing",
        help="save the .rrd recording of failing runs (default), all or none",
    )
    e.add_argument(
        "--bag",
        action="store_true",
        help="also write each recorded run as a ROS 2 bag, OUT/bags/RUN_ID/ (docs/ros.md)",
    )
    e.add_argument(
        "--fork",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="fork runs that differ only in their design from one reference run, with the "
        "same results (default), or, with --no-fork, run every run in full",
    )
    e.add_argument(
        "--log-every",
        type=int,
        default=None,
        metavar="N",
        help="recordings log every Nth frame's images (default "
        f"{RECORD_LOG_EVERY}; the replay command records every frame)",
    )
    e.add_argument(
        "--dry-run",
        action="store_true",
        help="print the run count and three example commands, run nothing",
    )
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.add_argument(
        "--strict",
        action="store_true",
        help="refuse a campaign whose scenarios load with warnings (a waypoint "
        "inside furniture, a check no run can meet...) instead of printing "
        "them",
    )
    e.add_argument(
        "--bench",
        action="store_true",
        help="benchmark: the same runs of one scenario (--scenarios, --backend, "
        "--resolution, --duration) on 1 worker and on N (--workers) workers; no CAMPAIGN",
    )
    e.add_argument(
        "--bench-runs",
        type=int,
        default=None,
        metavar="N",
        help="with --bench: runs per measurement (default 40)",
    )
    e.add_argument(
        "--bench-repeats",
        type=int,
        default=None,
        metavar="N",
        help="with --bench: measurements each way (default 3; medians)",
    )
    return p


def _merge_options(data, args):
    """The command-line values into the campaign's table, each checked first: an error
    names the option, not the campaign file. Returns what the command line gave, as
    ``load_campaign``'s ``command_line``."""
    from fpga_robotics.scenario.load import _parse_value  # lazy: the run stack (~1 s)

    if args.scenarios is not None:
        data["scenarios"] = [s.strip() for s in args.scenarios.split(",") if s.strip()]
        if not data["scenarios"]:
            raise UsageError(
                f"--scenarios needs scenario names or .toml paths (A,B), got {args.scenarios!r}"
            )
    if args.seeds is not None:
        text = args.seeds.strip()
        parts = [s.strip() for s in text.split(",")]
        data["seeds"] = (
            [int(s) for s in parts if s]
            if "," in text and all(s.isdigit() for s in parts if s)
            else text
        )
        parse_seeds(data["seeds"], where="--seeds", forms="A-B (e.g. 0-19) or A,B,C")
    for key in ("backend", "resolution", "duration", "shadow", "design", "ports", "timeout"):
        value = getattr(args, key)
        if value is not None:
            data[key] = value
    if args.fixed is not None:
        for item in args.fixed:
            if not item.partition("=")[0].strip() or "=" not in item:
                raise UsageError(f"--set needs KEY=VALUE (e.g. robot.mass=12), got {item!r}")
        data["set"] = list(data.get("set", [])) + args.fixed
    given_axes = set()
    for item in args.grid:
        key, sep, text = item.partition("=")
        values = _parse_value(text) if sep else None
        if not key.strip() or not isinstance(values, list) or not values:
            raise UsageError(
                f"--grid needs KEY=[V1, V2, ...] (a TOML list of at least one value), got {item!r}"
            )
        # A second --grid of one key would replace the first's values unseen.
        if key.strip() in given_axes:
            raise UsageError(
                f"--grid {key.strip()} is given twice: give all its values in one list"
            )
        given_axes.add(key.strip())
        grid = data.get("grid") if isinstance(data.get("grid"), dict) else {}
        data["grid"] = {**grid, key.strip(): values}
    given = {
        k: True
        for k in ("scenarios", "backend", "duration", "resolution", "shadow", "design", "ports")
        if getattr(args, k) is not None
    }
    grid = [item.partition("=")[0].strip() for item in args.grid]
    return {**given, "set": args.fixed or [], "grid": grid}


def _campaign(args):
    if args.campaign is None:
        if args.scenarios is None:
            raise UsageError(
                "give a campaign (a shipped name: "
                f"{', '.join(shipped_campaigns())}; or a .toml file), or "
                "--scenarios"
            )
        data, source = {"name": "campaign"}, ""
    else:
        data, path = read_campaign_file(args.campaign)
        source = str(path)
    command_line = _merge_options(data, args)
    return load_campaign(data, source=source, command_line=command_line)


def _check_options(args):
    for name in ("max_runs", "bench_runs", "bench_repeats", "log_every"):
        value = getattr(args, name)
        if value is not None and value < 1:
            raise UsageError(f"--{name.replace('_', '-')} must be >= 1, got {value}")
    # Here, not with the campaign: --bench takes --duration too.
    if args.duration is not None and not 0 < args.duration < math.inf:
        raise UsageError(f"--duration must be a finite number of seconds > 0, got {args.duration}")
    if args.timeout is not None and not 0 < args.timeout < math.inf:
        raise UsageError(f"--timeout must be a finite number of seconds > 0, got {args.timeout}")
    if args.bag and args.record == "none":
        raise UsageError(
            "--bag writes the recorded runs as ROS 2 bags: it needs --record "
            "failing (the default) or all"
        )
    if args.log_every is not None and args.record == "none":
        raise UsageError(
            "--log-every shapes the recordings: it needs --record failing (the default) or all"
        )
    check_cluster_options(args.workers, args.scheduler)


#: The options ``--bench`` takes: what its runs are and the workers it compares; it runs no
#: campaign and writes no results.
BENCH_OPTIONS = (
    "bench",
    "workers",
    "scenarios",
    "backend",
    "resolution",
    "duration",
    "bench_runs",
    "bench_repeats",
)


def _check_bench_options(args, parser):
    """``--bench`` with what it does not use, or ``--bench-*`` without it: ``UsageError``
    naming the option (it would be ignored)."""
    if not args.bench:
        for name in ("bench_runs", "bench_repeats"):
            if getattr(args, name) is not None:
                raise UsageError(f"--{name.replace('_', '-')} goes with --bench")
        return
    if args.campaign is not None:
        raise UsageError(
            f"--bench measures runs of its own (--scenarios NAME, --backend, --resolution, "
            f"--duration), not a campaign: leave out {args.campaign}"
        )
    for action in parser._actions:  # the options as given against their defaults
        given = getattr(args, action.dest, action.default) != action.default
        if given and action.option_strings and action.dest not in BENCH_OPTIONS:
            name = action.option_strings[0]
            if isinstance(action, argparse.BooleanOptionalAction) and not getattr(
                args, action.dest
            ):  # the option as given: --no-fork, not --fork
                name = "--no-" + name.removeprefix("--")
            raise UsageError(
                f"--bench runs no campaign and writes no results: {name} does not apply to it"
            )
    if args.scenarios is not None and "," in args.scenarios:
        raise UsageError(f"--bench measures one scenario, got --scenarios {args.scenarios}")


def _dry_run(campaign, args):
    plan = make_plan(campaign)
    if args.max_runs:
        plan.keep_first(args.max_runs)
    runs = plan.runs
    print(
        f"campaign {campaign.name}: {len(runs)} runs "
        f"({len(plan.builds)} design parameter set(s) to build)"
    )
    step = max(1, len(runs) // 3)
    for spec in runs[::step][:3]:
        print(f"  {spec.replay()}")
    return 0


def _report(argv, prog):
    p = CommandParser(
        prog=f"{prog} report",
        description="Rebuild report.html from a campaign's results. Exit status: 0 when every "
        "run passed, 1 when some did not or never ran, 2 for a usage error.",
    )
    p.add_argument("dir", metavar="DIR", help="the campaign's results folder")
    p.add_argument(
        "--exit-zero",
        action="store_true",
        help="exit 0 whatever the runs' results (a usage error still exits 2)",
    )
    args = p.parse_args(argv)

    if not args.dir.strip() or not Path(args.dir).is_dir():
        raise UsageError(f"{args.dir!r} is not a folder of campaign results")
    print(report_dir(args.dir))
    print(f"report: {Path(args.dir) / 'report.html'}")
    # As the campaign's own exit code: a CI step that only rebuilds the report still fails.
    return 0 if args.exit_zero or dir_passed(args.dir) else 1


def main(argv=None, prog=PROG):
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["report"]:
        return _report(argv[1:], prog)
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    _check_options(args)
    _check_bench_options(args, parser)
    if args.bench:
        from fpga_robotics.bench.sweep import bench  # lazy: the run stack (~1 s)

        return bench(args)
    campaign = _campaign(args)
    from fpga_robotics.sweep.sanity import report_campaign_warnings  # lazy: the run stack (~1 s)

    report_campaign_warnings(campaign, args.strict, sys.stderr, UsageError)
    # --dry-run too: it says the command would run. An empty --out is refused, not taken
    # for the default (Path("") would be the current folder).
    out = check_output_dir(
        args.out if args.out is not None else Path("runs") / "sweeps" / campaign.name,
        what="--out",
    )
    if args.dry_run:
        return _dry_run(campaign, args)

    def echo(text):
        if not args.quiet:
            print(text, file=sys.stderr, flush=True)

    try:
        rows = run_campaign(
            campaign,
            out,
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            record=args.record,
            timeout=args.timeout,
            max_runs=args.max_runs,
            quiet=args.quiet,
            echo=echo,
            log_every=args.log_every or RECORD_LOG_EVERY,
            bag=args.bag,
            fork=args.fork,
        )
    except KeyboardInterrupt:
        kept = len(load_rows(out))
        unreported = (
            f" (no report.html: `{prog} report {out}` writes it)"
            if kept and not (out / "report.html").exists()
            else ""
        )
        print(
            f"interrupted: {kept} finished run(s) kept in {out}{unreported}; continue with "
            f"--resume",
            file=sys.stderr,
        )
        raise
    axes = campaign.axes
    print(format_report(rows, axes, campaign.known_limits))
    print(
        f"results: {out / 'results.parquet'}, {out / 'results.csv'}; report: {out / 'report.html'}"
    )
    # A failure a [[known_limits]] entry explains is a limit of the design, not a regression.
    return 0 if campaign_passed(rows, campaign.known_limits) else 1


if __name__ == "__main__":  # python -m fpga_robotics.cli.sweep: as fpga-robotics sweep
    from fpga_robotics.cli import run_command

    run_command("sweep")
