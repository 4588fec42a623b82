"""``fpga-robotics ports``: write the port map of the exported follow_target (``--example``)
or check a port map file (docs/foreign.md)."""

from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.sim.backends.port_map import load_port_map, write_follow_target_port_map

__all__ = ["build_parser", "main"]


def build_parser(prog="fpga-robotics ports"):
    parser = CommandParser(prog=prog, description="Write the port map of the exported "
                           "follow_target (--example) or check a port map file.")
    parser.add_argument("path", help="the port map (TOML)")
    parser.add_argument("--example", action="store_true",
                        help="write the follow_target example to PATH (not replacing a file)")
    return parser


def main(argv=None, prog="fpga-robotics ports"):
    args = build_parser(prog).parse_args(argv)
    if args.example:
        write_follow_target_port_map(args.path)
        print(f"wrote {args.path}")
        return 0
    port_map = load_port_map(args.path)
    connectors = "".join(f", connectors.{kind}" for kind in port_map.connectors)
    print(f"{args.path}: {port_map.top}, outputs {', '.join(port_map.outputs)}{connectors}")
    return 0
