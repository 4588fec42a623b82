"""The designs a scenario can run: the built-in ones and those registered by users
(``builtin.py``), and the shipped port maps of foreign Verilog designs (``port_maps/``)."""

from fpga_robotics.designs.builtin import TOPS, Top, get_top, register_top

__all__ = ["TOPS", "Top", "get_top", "register_top"]
