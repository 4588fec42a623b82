"""The mutant netlist as a design the backends run: one Verilator build holds every mutant,
``mutsel`` (a ``[runtime]`` input of its port map) picks one between runs."""

import os

from ..sim.backends.foreign import ForeignVerilatorBackend
from ..sim.backends.port_map import follow_target_port_map
from ..sim.files import write_atomic
from ..sim.mutation import MUTATION_SELECT, mutant_netlist

__all__ = ["NETLIST_NAME", "PORTS_NAME", "open_mutant_design", "write_mutant_design"]

NETLIST_NAME = "mutants.v"
PORTS_NAME = "mutants_ports.toml"


def write_mutant_design(params, mutants, folder):
    """Write the netlist and its port map into ``folder``; return their paths."""
    os.makedirs(folder, exist_ok=True)
    netlist = os.path.join(folder, NETLIST_NAME)
    ports = os.path.join(folder, PORTS_NAME)
    write_atomic(netlist, mutant_netlist(params, mutants), what="mutant netlist")
    write_atomic(
        ports,
        follow_target_port_map(params)
        + f"\n# The mutant select (0: the design itself).\n[runtime]\n"
        f"{MUTATION_SELECT} = 0\n",
        what="port map",
    )
    return netlist, ports


def open_mutant_design(params, netlist, ports, *, on_build=None):
    """A backend of the mutant netlist (built once, then loaded from the cache)."""
    return ForeignVerilatorBackend(params, files=[netlist], port_map=ports, on_build=on_build)
