"""``python -m fpga_robotics.run``: the same as ``fpga-robotics run`` (``cli/run.py``)."""

from fpga_robotics.cli.run import cli

if __name__ == "__main__":
    cli()
