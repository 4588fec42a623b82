"""``fpga-robotics formal [--design REF [--param NAME=VALUE ...]] [--only NAME] [--depth N]``: prove the gateware's promises.

One row a check (its name, mode, depth, result and time) as each is done; a failed check's
counterexample VCD goes to ``--trace-dir`` and its row says where. The checks run in
``fpga_robotics.flow.formal``. Exit code 1 when a check fails.
"""

import os
from concurrent.futures import ThreadPoolExecutor

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.param_options import (
    add_define_argument,
    add_design_param_argument,
    defines_from_items,
    design_params_from_items,
)
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.flow.formal import (
    default_trace_dir,
    design_checks,
    end_running,
    formal_env,
    run_check,
    select,
)
from fpga_robotics.sim.files import check_output_dir

__all__ = ["build_parser", "main"]


def _row(cells, widths):
    return "  ".join(f"{c:<{w}}" for c, w in zip(cells, widths)).rstrip()


def build_parser(prog="fpga-robotics formal"):
    parser = CommandParser(
        prog=prog,
        description="Prove the gateware's promises with SymbiYosys and Yices (docs/formal.md).",
    )
    parser.add_argument(
        "--only",
        action="append",
        metavar="NAME",
        help="run only this check, or every check whose name starts with "
        "NAME. or NAME@ (repeatable)",
    )
    parser.add_argument(
        "--depth",
        type=int,
        metavar="N",
        help="cycles to search (bmc, cover) or the induction length (prove), "
        "instead of each check's own",
    )
    parser.add_argument(
        "--jobs",
        type=int,
        default=min(2, os.cpu_count() or 1),
        metavar="N",
        help="checks run at once (default: %(default)s)",
    )
    parser.add_argument(
        "--trace-dir",
        default=None,
        metavar="DIR",
        help="where counterexample VCDs go (default: "
        "$FPGA_ROBOTICS_CACHE/formal-traces, else "
        "~/.cache/fpga_robotics/formal-traces)",
    )
    parser.add_argument("--list", action="store_true", help="list the checks and exit")
    parser.add_argument(
        "--design",
        metavar="REF",
        help="check the properties this design declares (FILE.py:Name or "
        "package.module:Name with formal_properties, docs/formal.md; or "
        "verilog:FILES, its assert and cover statements) instead "
        "of FollowTarget's",
    )
    add_design_param_argument(parser)
    add_define_argument(parser)
    parser.add_argument(
        "--ports",
        "--port-map",
        dest="ports",
        metavar="PORTS.toml",
        help="with --design verilog:FILES: its port map (names the top module)",
    )
    return parser


def main(argv=None, prog="fpga-robotics formal"):
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    if args.list:
        # The list shows which checks and their own depths: what runs them is ignored.
        others = parser.given_options(
            args, ignore={"list", "design", "param", "define", "ports", "only"}
        )
        if others:
            raise UsageError(
                f"--list takes only --design, --param, --define, --ports and --only; got "
                f"{', '.join(others)}"
            )
    if args.depth is not None and args.depth < 1:
        raise UsageError(f"--depth must be at least 1, got {args.depth}")
    if args.jobs < 1:
        raise UsageError(f"--jobs must be at least 1, got {args.jobs}")

    checks = select(
        design_checks(
            args.design,
            design_params_from_items(args.param),
            args.ports,
            defines_from_items(args.define),
        ),
        args.only,
    )
    if args.list:
        width = max(len(c.name) for c in checks)
        for c in checks:
            print(f"{c.name:<{width}}  {c.mode:<5}  {c.depth:>3}  {c.promise}")
        return 0
    # An empty --trace-dir is refused by the check, not taken for the default.
    trace_dir = check_output_dir(
        args.trace_dir if args.trace_dir is not None else default_trace_dir(),
        what="counterexample folder",
    )
    env = formal_env()
    widths = (max(len(c.name) for c in checks), 5, 5, 7, 7)
    print(_row(("property", "mode", "depth", "result", "time"), widths))
    results = []

    def one(check):
        return run_check(check, depth=args.depth, trace_dir=trace_dir, env=env)

    pool = ThreadPoolExecutor(max_workers=args.jobs)
    try:
        for r in pool.map(one, checks):  # in the listed order, as each is done
            results.append(r)
            print(
                _row((r.name, r.mode, str(r.depth), r.status, f"{r.seconds:.1f}s"), widths),
                flush=True,
            )
            if not r.passed:
                if r.detail:
                    print(f"    {r.detail}")
                if r.trace:
                    print(f"    counterexample: {r.trace}")
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        end_running()
        raise
    pool.shutdown()
    failed = [r for r in results if not r.passed]
    total = sum(r.seconds for r in results)
    print(
        f"{len(results) - len(failed)} of {len(results)} checks passed "
        f"({total:.1f}s of solver time)"
    )
    return 1 if failed else 0


if __name__ == "__main__":  # python -m fpga_robotics.cli.formal: as fpga-robotics formal
    from fpga_robotics.cli import run_command

    run_command("formal")
