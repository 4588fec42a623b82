"""``fpga-robotics readback FILE.rrd``: what a saved recording holds, entity by entity, and its size per frame."""

from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.viz.readback import read_rrd, summary_lines

__all__ = ["build_parser", "main"]


def build_parser(prog="fpga-robotics readback"):
    parser = CommandParser(
        prog=prog,
        description="What a saved .rrd recording holds: its "
        "size, its frames and the rows of each entity.",
    )
    parser.add_argument("path", metavar="FILE.rrd", help="the recording")
    return parser


def main(argv=None, prog="fpga-robotics readback"):
    args = build_parser(prog).parse_args(argv)
    for line in summary_lines(read_rrd(args.path), args.path):
        print(line)
    return 0


if __name__ == "__main__":  # python -m fpga_robotics.cli.readback: as fpga-robotics readback
    from fpga_robotics.cli import run_command

    run_command("readback")
