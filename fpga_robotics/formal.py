"""``python -m fpga_robotics.formal``: the same as ``fpga-robotics formal`` (``cli/formal.py``)."""

if __name__ == "__main__":
    from fpga_robotics.cli import run_command

    run_command("formal")
