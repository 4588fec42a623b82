"""Export ``FollowTarget`` as one self-contained Verilog file.

    python -m fpga_robotics.export -o build/follow_target.v [--width 320 --height 240 ...]
    python -m fpga_robotics.export --preset published -o build/published.v   (docs/published.md)
    python -m fpga_robotics.export --board ulx3s-85f -o DIR [--bitstream]   (board top + LPF)

Every ``FollowTargetParams`` field is an option (``--diff-min 5``, ``--base-dps 0,400,...``);
``--preset NAME`` starts from a preset, the other options on top. A bad value or an unknown
preset prints what is wrong and exits with code 2.
"""

import argparse
import os

from .board_build import add_board_arguments, run_board
from .errors import UsageError, run_cli
from .hw.verilog import TOP_NAME, generate_verilog
from .param_options import add_param_arguments, params_from_args
from .sim.files import check_output_path, write_atomic

__all__ = ["build_parser", "main"]


def build_parser(prog="python -m fpga_robotics.export"):
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Write the FollowTarget design as one self-contained Verilog file "
                    f"(top module {TOP_NAME}).",
    )
    parser.add_argument("-o", "--output", default=os.path.join("build", f"{TOP_NAME}.v"),
                        help="output Verilog file (default: %(default)s); its directory is "
                             "created if missing; with --board: the output directory "
                             "(default build/<board>)")
    add_board_arguments(parser)
    add_param_arguments(parser)
    return parser


def main(argv=None, prog="python -m fpga_robotics.export"):
    parser = build_parser(prog)
    args = parser.parse_args(argv)  # a bad option: argparse's message and exit code 2
    params = params_from_args(args)
    if args.board is not None:  # a board top instead (fpga_robotics.board_build)
        out_dir = args.output
        if out_dir == parser.get_default("output"):
            out_dir = os.path.join("build", args.board)
        return run_board(args, params, out_dir)
    if args.bitstream:
        raise UsageError("--bitstream needs --board NAME (e.g. --board ulx3s-85f)")
    if args.seed is not None:
        raise UsageError("--seed is nextpnr's placement seed: it needs --board NAME --bitstream")
    if os.path.isdir(args.output):
        raise UsageError(
            f"{args.output} is a directory; give the Verilog file's path, e.g. "
            f"{os.path.join(args.output, TOP_NAME + '.v')}"
        )
    check_output_path(args.output, what="Verilog file")
    write_atomic(args.output, generate_verilog(params), what="Verilog file")
    preset = f", preset {args.preset}" if args.preset is not None else ""
    print(f"wrote {args.output} ({params.width}x{params.height}{preset}, module {TOP_NAME})")
    return 0


if __name__ == "__main__":
    run_cli(main, prog="python -m fpga_robotics.export")
