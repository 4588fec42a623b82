from ..errors import run_cli
from .cli import main

run_cli(main, prog="python -m fpga_robotics.mutation")
