"""``python -m fpga_robotics.mutation``: the same as ``fpga-robotics mutate``
(``cli/mutate.py``)."""

from fpga_robotics.cli import run_command

run_command("mutate")
