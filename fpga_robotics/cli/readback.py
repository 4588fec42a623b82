"""``python -m fpga_robotics.cli.readback FILE.rrd`` (or ``fpga-robotics readback``):
what a saved recording holds, entity by entity, and its size per frame."""

import sys

from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.viz.readback import read_rrd, summary_lines

__all__ = ["main"]


def main(argv=None, prog="fpga-robotics readback"):
    if not argv or len(argv) != 1 or argv[0].startswith("-"):
        raise UsageError(f"usage: {prog} FILE.rrd")
    for line in summary_lines(read_rrd(argv[0]), argv[0]):
        print(line)
    return 0


if __name__ == "__main__":
    run_cli(main, sys.argv[1:], prog="fpga_robotics.cli.readback")
