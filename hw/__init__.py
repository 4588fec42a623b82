"""Amaranth gateware of fpga-robotics.

Nothing in this package imports host-side code (simulation, physics, viewer): it describes
hardware only, so that what runs in simulation is exactly what goes on the board.
"""
