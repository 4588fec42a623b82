"""``python -m fpga_robotics.bench [WHAT]``: the same as ``fpga-robotics bench [WHAT]``."""

from fpga_robotics.cli import main

main(["bench", *__import__("sys").argv[1:]])
