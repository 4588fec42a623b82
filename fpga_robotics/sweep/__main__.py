"""``python -m fpga_robotics.sweep``: see ``fpga_robotics.cli.sweep``."""

if __name__ == "__main__":  # worker processes import this module again: do nothing there
    from fpga_robotics.cli.sweep import cli

    cli()
