"""``python -m fpga_robotics.export``: the same as ``fpga-robotics export``; from Python,
``generate_verilog(params)`` (``flow/export.py``)."""

from fpga_robotics.flow.export import generate_verilog, main

__all__ = ["generate_verilog", "main"]

if __name__ == "__main__":
    from fpga_robotics.cli.errors import run_cli

    run_cli(main, prog="fpga-robotics export")
