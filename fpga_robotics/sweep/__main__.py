"""``python -m fpga_robotics.sweep``: see ``fpga_robotics.sweep.cli``."""

if __name__ == "__main__":  # worker processes import this module again: do nothing there
    from .cli import cli

    cli()
