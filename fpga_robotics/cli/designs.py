"""``fpga-robotics designs [REF]``: the designs a run can name (built-in, installed through
the ``fpga_robotics.designs`` entry points, or the reference given), with their ports, the
connectors they bind and the outputs recorded under their own names."""

import dataclasses
import re
import sys

from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.cli.param_options import (
    add_define_argument,
    defines_from_items,
    design_params_from_items,
)
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.designs.builtin import TOPS, connector_kinds
from fpga_robotics.designs.reference import DesignError, entry_point_designs, resolve_design

__all__ = ["describe", "main"]


def build_parser(prog):
    p = CommandParser(
        prog=prog,
        description="List the designs a scenario's design.top (or run --design) can "
        "name, with their ports and the connectors they bind.",
    )
    p.add_argument(
        "reference",
        nargs="?",
        metavar="REF",
        help="describe only this design: a built-in name, FILE.py:Name, "
        "package.module:Name or verilog:TOP.v[,MORE.v] with --ports",
    )
    p.add_argument(
        "--param",
        dest="params",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a parameter of REF (repeatable; TOML values)",
    )
    p.add_argument("--ports", metavar="PORTS.toml", help="the port map of a verilog: REF")
    add_define_argument(p)
    return p


def describe(spec, origin):
    """Lines describing a ``DesignSpec``."""
    lines = [f"{spec.reference}  ({origin})  {spec.description}"]
    if spec.ports:
        lines.append("  ports: " + ", ".join(f"{d} {n}[{w}]" for n, (d, w) in spec.ports.items()))
    else:
        lines.append("  ports: as Verilator reads them from the files (the port map names them)")
    binds = "; ".join(
        f"{kind} ({', '.join(f'{pin}={port}' for pin, port in pins.items())})"
        for kind, pins in spec.bindings.items()
    )
    lines.append(f"  connectors: {binds or 'none'}")
    lines.append(f"  recorded outputs: {', '.join(spec.extra_outputs) or 'none'}")
    undriven = _undriven_inputs(spec)
    if undriven:
        lines.append(
            f"  undriven inputs: {', '.join(undriven)} (no connector binds them: a run refuses "
            'the design unless a [[robot.sensors]] table binds each, ports = {PIN = "PORT"})'
        )
    return lines


def _undriven_inputs(spec):
    """The inputs of an Amaranth design that no connector it binds drives (a run refuses
    them: nothing would drive them). A Verilog design's port map must drive every input,
    which ``checked_verilog`` checks."""
    if spec.kind == "verilog":
        return []
    bound = set()
    for pins in spec.bindings.values():
        for port in pins.values():  # a stream binds PORT__valid and PORT__payload
            bound |= {port, f"{port}__valid", f"{port}__payload"}
    names = []
    for name, (direction, _) in spec.ports.items():
        if direction == "in" and name not in bound:
            # A pixel stream's two ports by the stream's name, as a camera table binds it.
            name = re.sub(r"__(valid|payload)$", "", name)
            if name not in names:
                names.append(name)
    return names


def checked_verilog(spec, ports):
    """A Verilog design's spec with its ports as Verilator reads them, the port map checked
    against them (names, directions, widths, every input driven, the connectors' pins):
    ``DesignError`` for the first mismatch."""
    from fpga_robotics.sim.backends.base import BackendError  # lazy: the simulator (~0.5 s)
    from fpga_robotics.sim.backends.foreign import ForeignDesign  # lazy: the simulator (~0.5 s)
    from fpga_robotics.sim.backends.port_map import load_port_map  # lazy: the simulator (~0.5 s)

    files = spec.reference[len("verilog:") :].split(",")
    port_map = load_port_map(ports)
    pins = bool(port_map.connectors or port_map.extra_outputs or not port_map.has_pixels)
    try:
        design = ForeignDesign(
            files,
            port_map,
            pins=pins,
            connector_kinds=connector_kinds(),
            overrides=spec.overrides,
        )
    except BackendError as exc:
        raise DesignError(f"{ports}: {exc}".splitlines()[0]) from None
    found = {
        name: ("in" if d == "input" else "out", width)
        for name, (d, width, _signed) in design.ports.items()
    }
    return dataclasses.replace(spec, ports=found, extra_outputs=tuple(port_map.extra_outputs))


def main(argv=None, prog="fpga-robotics designs"):
    args = build_parser(prog).parse_args(argv)
    params = design_params_from_items(args.params)
    if args.reference is None:
        if params or args.ports or args.define:
            raise UsageError("--param, --define and --ports describe a design REF: give one")
        for name in TOPS:
            print("\n".join(describe(resolve_design(name), "built-in")))
        for name, target in entry_point_designs().items():
            print("\n".join(describe(resolve_design(name), f"installed: {target}")))
        return 0
    if args.ports is not None and not args.reference.startswith("verilog:"):
        raise UsageError("--ports is the port map of a Verilog design: it goes with verilog:FILES")
    if args.define and not args.reference.startswith("verilog:"):
        raise UsageError("--define sets `define macros of a Verilog design (verilog:FILES)")
    spec = resolve_design(
        args.reference,
        params,
        ports=args.ports,
        option="--param",
        defines=defines_from_items(args.define),
    )
    if spec.kind == "verilog":
        spec = checked_verilog(spec, args.ports)
    origin = {"builtin": "built-in", "amaranth": "Amaranth", "verilog": "Verilog"}[spec.kind]
    print("\n".join(describe(spec, origin)))
    return 0


if __name__ == "__main__":
    run_cli(main, sys.argv[1:], prog="fpga-robotics designs")
