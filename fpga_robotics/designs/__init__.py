"""The designs a scenario can run: the built-in ones and those registered by users
(``builtin.py``), references to designs of one's own (``reference.py``: ``FILE.py:Name``,
``module:Name``, ``verilog:FILES``, installed entry points), and the shipped port maps of
foreign Verilog designs (``port_maps/``)."""

from fpga_robotics.designs.builtin import TOPS, Top, get_top, register_top
from fpga_robotics.designs.reference import DesignError, DesignSpec, resolve_design

__all__ = ["TOPS", "DesignError", "DesignSpec", "Top", "get_top", "register_top", "resolve_design"]
