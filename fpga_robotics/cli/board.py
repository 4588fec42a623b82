"""``fpga-robotics board``: export a board top (Verilog + LPF) and optionally build its
bitstream (also ``fpga-robotics export --board NAME``); the flow is ``fpga_robotics.flow.board``.
A timing failure or a failed tool is exit code 1."""

import os
import sys

from fpga_robotics.cli.designs import checked_verilog
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.param_options import (
    add_define_argument,
    add_design_param_argument,
    add_param_arguments,
    defines_from_items,
    design_params_from_items,
    given_followtarget_options,
    params_from_args,
    refuse_followtarget_options,
)
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.designs.reference import is_builtin, resolve_design
from fpga_robotics.flow.board import (
    board_factory,
    board_names,
    board_ports,
    build_bitstream,
    export_board,
    header_pins,
)
from fpga_robotics.flow.board_verilog import check_yosys_reads, verilog_files
from fpga_robotics.sim.files import check_output_dir

__all__ = ["add_board_arguments", "main", "run_board"]


def add_board_arguments(parser):
    """The ``--board``/``--bitstream``/``--seed`` options (shared with ``export``)."""
    parser.add_argument(
        "--board",
        metavar="NAME",
        help=f"export a board top instead: one of {', '.join(board_names())}",
    )
    parser.add_argument(
        "--bitstream",
        action="store_true",
        help="with --board: also run synthesis, place and route and packing",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=None,
        help="with --bitstream: nextpnr placement seed (default: 1)",
    )


#: The placement seeds nextpnr takes (it reads ``--seed`` as a signed 64-bit integer).
SEEDS = range(-(2**63), 2**63)


def run_board(args, params, out_dir, prog="fpga-robotics board", design=None):
    """Export (and optionally build) ``args.board`` into ``out_dir`` (with ``design``, a
    ``DesignSpec``, on it instead of FollowTarget); returns an exit code."""
    board_factory(args.board)
    if args.seed is not None and not args.bitstream:
        raise UsageError("--seed is nextpnr's placement seed: it needs --bitstream")
    if args.seed is not None and args.seed not in SEEDS:
        raise UsageError(
            f"--seed must be from -2**63 to 2**63-1 (nextpnr's placement seeds); got {args.seed}"
        )
    if design is not None:
        board_ports(design)  # a port the board cannot serve: one line, nothing written
        if design.kind == "verilog":
            verilog_files(design)  # an included file not found: said as the board says it
            # Read as ports and run read it: a syntax error, or a map that does not fit
            # the design, is one line here, before anything is written.
            design = checked_verilog(design, args.ports)
            check_yosys_reads(design)  # the board's synthesiser reads it too
    seed = 1 if args.seed is None else args.seed
    check_output_dir(out_dir, what="board output folder")
    if not args.bitstream:
        written = export_board(args.board, out_dir, params, design=design)
        if design is not None:
            for port, pin, site in header_pins(design):
                print(f"{port}: header {pin} (site {site})")
        for path in written:
            if path.endswith((".v", ".lpf")):
                print(f"wrote {path}")
        print(f"wrote {len(written)} files for board {args.board} in {out_dir}")
        return 0
    try:
        report = build_bitstream(args.board, out_dir, params, seed=seed, design=design)
    except RuntimeError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1
    print(report.format())
    if not report.timing_ok:
        print(f"{prog}: error: timing failed (a clock is slower than required)", file=sys.stderr)
        return 1
    print(f"wrote {report.bitstream}")
    return 0


def main(argv=None, prog="fpga-robotics board"):
    parser = CommandParser(
        prog=prog,
        description="Export a board top (Verilog + LPF) and optionally build its bitstream.",
    )
    boards = board_names()
    # With one board there is nothing to choose: it is the default.
    parser.add_argument(
        "--board",
        metavar="NAME",
        required=len(boards) > 1,
        default=boards[0] if len(boards) == 1 else None,
        help=f"one of {', '.join(boards)}",
    )
    parser.add_argument(
        "-o",
        "--output",
        metavar="DIR",
        default=None,
        help="output directory (default: build/<board>)",
    )
    parser.add_argument(
        "--bitstream", action="store_true", help="run synthesis, place and route and packing too"
    )
    parser.add_argument("--seed", type=int, default=None, help="nextpnr seed (default: 1)")
    parser.add_argument(
        "--design",
        metavar="REF",
        help="put this design of your own on the board instead of FollowTarget "
        "(a built-in name such as turret_tracker, FILE.py:Name, package.module:Name, "
        "verilog:FILES with --ports; "
        "docs/your_design.md): the camera stream, the wheels and its connector pins on "
        "header pins",
    )
    parser.add_argument(
        "--ports",
        metavar="MAP",
        help="with --design verilog:FILES: the design's port map (docs/foreign.md)",
    )
    add_design_param_argument(parser)
    add_define_argument(parser)
    add_param_arguments(parser)
    args = parser.parse_args(argv)
    params = params_from_args(args)
    design = None
    if args.design is not None:
        reference = args.design.strip()
        if args.ports is not None and not reference.startswith("verilog:"):
            raise UsageError(
                "--ports is the port map of a Verilog design: it goes with --design verilog:FILES"
            )
        if is_builtin(reference):
            _refuse_builtin_parameters(args, reference)
        # The board top's own options would be silently ignored with a design of one's own.
        refuse_followtarget_options(args, "--design REF puts a design of your own on the board")
        if args.define and not reference.startswith("verilog:"):
            raise UsageError("--define sets `define macros of a Verilog design (verilog:FILES)")
        design = resolve_design(
            args.design,
            design_params_from_items(args.param),
            ports=args.ports,
            option="--param",
            defines=defines_from_items(args.define),
        )
        design.require_defined_domains()  # the board drives the sync domain's clock only
    elif args.param or args.ports or args.define:
        given = "--param" if args.param else "--define" if args.define else "--ports"
        raise UsageError(f"{given} goes with --design REF (a design of your own)")
    # An empty -o is refused by run_board's check, not replaced by the default.
    out = args.output if args.output is not None else os.path.join("build", args.board)
    return run_board(args, params, out, prog, design=design)


def _refuse_builtin_parameters(args, name):
    """A built-in design goes on the board at its default parameters: an option or
    ``--param`` for it is a usage error saying so (it would be ignored, or sent to
    ``--param``, which a built-in design does not take)."""
    given = given_followtarget_options(args) + [f"--param {item}" for item in args.param]
    if not given:
        return
    options = ", ".join(given)
    if name == "follow_target":
        raise UsageError(
            f"{options}: design 'follow_target' is the board's own top: run fpga-robotics "
            "board without --design, with its options (--diff-min 5, ...)"
        )
    raise UsageError(
        f"{options}: the built-in design {name} goes on the board at its default parameters; "
        f"with others, export its Verilog (fpga-robotics export --top {name} ...) and give "
        "that as --design verilog:FILE.v --ports MAP"
    )


if __name__ == "__main__":  # python -m fpga_robotics.cli.board: as fpga-robotics board
    from fpga_robotics.cli import run_command

    run_command("board")
