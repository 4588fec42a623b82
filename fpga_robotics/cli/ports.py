"""``fpga-robotics ports``: write the port map of the exported follow_target (``--example``)
or check a port map file (docs/foreign.md); with ``--design verilog:FILES`` the map is checked
against the design's real ports as Verilator reads them (names, directions, widths, every input
driven, the connectors' pins)."""

from fpga_robotics.cli.designs import checked_verilog
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.param_options import (
    add_define_argument,
    defines_from_items,
    design_params_from_items,
)
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.designs.builtin import connector_kinds
from fpga_robotics.designs.reference import DesignError, resolve_design
from fpga_robotics.sim.backends.port_map import (
    check_connector_names,
    load_port_map,
    write_follow_target_port_map,
)

__all__ = ["build_parser", "main"]


def build_parser(prog="fpga-robotics ports"):
    parser = CommandParser(
        prog=prog,
        description="Write the port map of the exported "
        "follow_target (--example) or check a port map file.",
    )
    parser.add_argument("path", metavar="PORTS.toml", help="the port map (TOML)")
    parser.add_argument(
        "--example",
        action="store_true",
        help="write the exported follow_target's map to PORTS.toml (not replacing a file); "
        "without --design",
    )
    parser.add_argument(
        "--design",
        metavar="verilog:TOP.v[,MORE.v]",
        help="check the map against this design's real ports",
    )
    parser.add_argument(
        "--param",
        dest="params",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="with --design: a parameter of its top, as a run sets it (repeatable)",
    )
    add_define_argument(parser)
    return parser


def main(argv=None, prog="fpga-robotics ports"):
    args = build_parser(prog).parse_args(argv)
    if args.design is not None and not args.design.startswith("verilog:"):
        # Before the --example hint, which names a check that takes Verilog only.
        raise DesignError(
            f"--design must be a Verilog design, verilog:TOP.v[,MORE.v], got "
            f"{args.design!r} (an Amaranth design needs no port map)"
        )
    if args.example and args.design is not None:
        # The example is follow_target's map: written "for" a design of one's own it would
        # name ports that design does not have.
        raise UsageError(
            "--example writes the exported follow_target's port map, not one for --design; "
            "write your design's map from it (docs/foreign.md), then check it with "
            f"fpga-robotics ports {args.path} --design {args.design}"
        )
    if (args.params or args.define) and args.design is None:
        # The widths they size are the design's: without it there is nothing to set.
        given = "--param" if args.params else "--define"
        raise UsageError(f"{given} sets a parameter or macro of the --design verilog:FILES")
    if args.example:
        write_follow_target_port_map(args.path)
        print(f"wrote {args.path}")
        return 0
    port_map = load_port_map(args.path)
    check_connector_names(port_map, connector_kinds())  # the connector kinds need no design
    if args.design is not None:
        params = design_params_from_items(args.params)
        _check_against_design(args.design, args.path, params, defines_from_items(args.define))
    connectors = "".join(f", connectors.{kind}" for kind in port_map.connectors)
    print(f"{args.path}: {port_map.top}, outputs {', '.join(port_map.outputs)}{connectors}")
    return 0


def _check_against_design(reference, path, params, defines):
    """Raise a one-line ``DesignError`` at the first way the map and the design, built with
    ``params`` and ``defines`` (``--param``, ``--define``), disagree."""
    spec = resolve_design(reference, params, ports=path, option="--param", defines=defines)
    spec = checked_verilog(spec, path)
    print(f"{path}: matches {reference} ({len(spec.ports)} ports)")


if __name__ == "__main__":  # python -m fpga_robotics.cli.ports: as fpga-robotics ports
    from fpga_robotics.cli import run_command

    run_command("ports")
