"""``python -m fpga_robotics.formal``: the same as ``fpga-robotics formal`` (``flow/formal.py``)."""

import sys

from fpga_robotics.flow.formal import main

if __name__ == "__main__":
    from fpga_robotics.cli.errors import run_cli

    run_cli(main, sys.argv[1:], prog="fpga-robotics formal")
