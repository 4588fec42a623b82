"""The mutant netlist as a design the backends run: one Verilator build holds every mutant,
``mutsel`` (a ``[runtime]`` input of its port map) picks one between runs."""

import json
import os
import re
import tomllib

from ..designs.reference import stream_ports
from ..hw.verilog import TOP_NAME
from ..loop.pin_frames import SETTLE_EDGES
from ..sim.backends.foreign import ForeignVerilatorBackend
from ..sim.backends.port_map import follow_target_port_map
from ..sim.files import write_atomic
from ..sim.mutation import MUTATION_SELECT, WATCH_PORT, mutant_netlist

__all__ = [
    "NETLIST_NAME",
    "PORTS_NAME",
    "WATCH_PORTS_NAME",
    "design_mutant_port_map",
    "netlist_has_reset",
    "open_mutant_design",
    "with_mutant_select",
    "write_mutant_design",
]

NETLIST_NAME = "mutants.v"
PORTS_NAME = "mutants_ports.toml"
#: The same port map with the watch output watched: for the unmutated design's runs only
#: (a mutant's run needs no watch, and its model runs faster without one).
WATCH_PORTS_NAME = "mutants_watch_ports.toml"
#: Where each mutant acts, watched at ``mutsel = 0`` (sim.mutant_watch).
_WATCH_TABLE = f'\n# Bit k-1 rises where mutant k would act.\n[watch]\nport = "{WATCH_PORT}"\n'


def write_mutant_design(params, mutants, folder):
    """Write the netlist and its port maps into ``folder`` (``PORTS_NAME``, and
    ``WATCH_PORTS_NAME`` with the watch); return the paths of the netlist and of the first."""
    os.makedirs(folder, exist_ok=True)
    netlist = os.path.join(folder, NETLIST_NAME)
    ports = os.path.join(folder, PORTS_NAME)
    write_atomic(netlist, mutant_netlist(params, mutants), what="mutant netlist")
    text = (
        follow_target_port_map(params)
        + f"\n# The mutant select (0: the design itself).\n[runtime]\n{MUTATION_SELECT} = 0\n"
    )
    write_atomic(ports, text, what="port map")
    write_atomic(os.path.join(folder, WATCH_PORTS_NAME), text + _WATCH_TABLE, what="port map")
    return netlist, ports


def open_mutant_design(params, netlist, ports, *, on_build=None):
    """A backend of the mutant netlist (built once, then loaded from the cache)."""
    return ForeignVerilatorBackend(params, files=[netlist], port_map=ports, on_build=on_build)


def _key(name):
    """A TOML key: bare when it can be, quoted otherwise."""

    return name if name.replace("_", "a").replace("-", "a").isalnum() else json.dumps(name)


def netlist_has_reset(verilog):
    """Whether the netlist's top has Amaranth's ``rst`` input (a design with a sync domain)."""

    return re.search(r"^\s*input\s+rst\s*;", verilog, re.MULTILINE) is not None


def design_mutant_port_map(spec, ports, *, reset=True, select=MUTATION_SELECT, watch=False):
    """TOML text: the port map of the mutant netlist of a design of one's own (``spec``, a
    resolved ``DesignSpec``; ``ports``: name -> ``Port`` as ``design_run.design_ports`` gives
    them), its bindings as the design declares them, ``mutsel`` a ``[runtime]`` input;
    ``reset``: whether the netlist has Amaranth's ``rst``; ``watch``: with ``[watch]`` its
    ``mutinf``."""

    q = json.dumps
    lines = [
        "# The mutant netlist of " + spec.reference.rpartition("/")[2] + " (generated).",
        f"top = {q(TOP_NAME)}",
        'clock = { port = "clk" }',
    ]
    if reset:
        lines.append('reset = { port = "rst" }')
    camera = spec.bindings.get("camera")
    if camera is not None:
        valid, payload = stream_ports(spec.bindings)
        lines.append(f"pixels = {{ valid = {q(valid)}, payload = {q(payload)} }}")
        if camera.get("color_sel"):
            lines.append(f"color = {{ port = {q(camera['color_sel'])} }}")
        if ports.get("frame_done") is not None and ports["frame_done"].direction == "out":
            # The wheels are read SETTLE_EDGES edges after frame_done, as `run` reads them.
            lines.append(
                f'result = {{ strobe = "frame_done", latency = {SETTLE_EDGES}, timeout = 100000 }}'
            )
        else:
            lines.append("result = { after_cycles = 1 }")
        if "filtered__valid" in ports and "filtered__payload" in ports:
            lines.append('filtered = { valid = "filtered__valid", payload = "filtered__payload" }')
    outputs = dict(spec.bindings.get("wheels", {}))
    if camera is not None:
        outputs.update({k: k for k in ("found", "proximity", "centroid_x", "centroid_leds")})
    out_lines = []
    for key, port in outputs.items():
        p = ports.get(port)
        if p is None or p.direction != "out":
            continue
        signed = "true" if p.signed else "false"
        out_lines.append(f"{key} = {{ port = {q(port)}, width = {p.width}, signed = {signed} }}")
    if out_lines:
        lines += ["", "[outputs]", *out_lines]
    for kind, pins in spec.bindings.items():
        if kind in ("wheels", "camera"):
            continue
        lines += ["", f"[connectors.{_key(kind)}]"]
        lines += [f"{_key(pin)} = {q(port)}" for pin, port in pins.items()]
    if spec.extra_outputs:
        lines += ["", "[extra_outputs]"]
        lines += [f"{_key(name)} = {q(name)}" for name in spec.extra_outputs]
    lines += ["", "# The mutant select (0: the design itself).", "[runtime]", f"{select} = 0", ""]
    return "\n".join(lines) + (_WATCH_TABLE if watch else "")


def with_mutant_select(port_map_text, select=MUTATION_SELECT, watch=False):
    """A Verilog design's port map (TOML text) with ``select`` a ``[runtime]`` input at 0:
    the port map of its mutant netlist; ``watch``: with ``[watch]`` its ``mutinf`` (None if
    the map watches an output of its own)."""

    line = f"{select} = 0  # the mutant select (0: the design itself)"
    if re.search(r"^\s*\[runtime\]\s*(#.*)?$", port_map_text, re.MULTILINE):
        text = re.sub(
            r"^(\s*\[runtime\]\s*(#.*)?)$",
            lambda m: m.group(1) + "\n" + line,
            port_map_text,
            count=1,
            flags=re.MULTILINE,
        )
    else:
        text = port_map_text.rstrip("\n") + "\n\n[runtime]\n" + line + "\n"
    if not watch:
        return text
    # A map that watches an output of its own keeps it: its mutants' runs are made in full.
    return None if "watch" in tomllib.loads(port_map_text) else text + _WATCH_TABLE
