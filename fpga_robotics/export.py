"""``python -m fpga_robotics.export``: the same as ``fpga-robotics export``
(``cli/export.py``); from Python, ``generate_verilog(params)`` (``flow/export.py``)."""

from fpga_robotics.flow.export import generate_verilog

__all__ = ["generate_verilog"]

if __name__ == "__main__":
    from fpga_robotics.cli import run_command

    run_command("export")
