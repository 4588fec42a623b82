"""Mutation coverage: how many gateware bugs do the unit frames (and the scenarios) catch?

``python -m fpga_robotics.mutation`` (``fpga-robotics mutate``): see ``cli.py`` and
docs/mutation.md. The mutants come from ``fpga_robotics.sim.mutation``.
"""
