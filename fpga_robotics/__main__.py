"""``python -m fpga_robotics``: the same as the ``fpga-robotics`` command."""

from .cli import main

main()
