"""``python -m fpga_robotics.sweep``: the same as ``fpga-robotics sweep`` (``cli/sweep.py``)."""

if __name__ == "__main__":  # worker processes import this module again: do nothing there
    from fpga_robotics.cli import run_command

    run_command("sweep")
