"""``python -m fpga_robotics.viz.bench``: the viewer benchmark, kept under its old name.

The benchmark is an application (``fpga_robotics.viewer_bench``); this module only forwards to
it, so that nothing in the viewer package depends on the application layer.
"""

if __name__ == "__main__":
    import sys

    from fpga_robotics.errors import run_cli
    from fpga_robotics.viewer_bench import main

    run_cli(main, sys.argv[1:], prog="fpga_robotics.viz.bench")
