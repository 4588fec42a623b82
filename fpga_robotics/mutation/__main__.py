from fpga_robotics.cli.errors import run_cli
from fpga_robotics.cli.mutate import main

run_cli(main, prog="python -m fpga_robotics.mutation")
