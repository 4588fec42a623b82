"""``python -m fpga_robotics.run``: the closed-loop demo (placeholder until the loop lands)."""

import sys

from .errors import UsageError, run_cli


def main(argv=None):
    raise UsageError("the closed loop is not built yet; see the README for what works today")


if __name__ == "__main__":
    run_cli(main, sys.argv[1:], prog="fpga_robotics.run")
