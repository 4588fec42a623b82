"""``python -m fpga_robotics.run``: the same as ``fpga-robotics run`` (``cli/run.py``)."""

if __name__ == "__main__":
    from fpga_robotics.cli import run_command

    run_command("run")
