"""Export a design as one self-contained Verilog file.

    fpga-robotics export -o build/follow_target.v [--width 320 --height 240 ...]
    fpga-robotics export --preset published -o build/published.v   (docs/published.md)
    fpga-robotics export --board ulx3s-85f -o DIR [--bitstream]   (board top + LPF)
    fpga-robotics export --top follow_target_safe [--stop-mm 250 --us-period-us ...]
    fpga-robotics export --top follow_line [--line-n-sensors 2 --variant ...]
    fpga-robotics export --top corridor_follow[_uart] [--corridor-keep-mm 500 --variant ...]
    fpga-robotics export --design my_design.py:MyDesign [--param NAME=VALUE ...] -o x.v
    fpga-robotics export --design follow_target_safe [--stop-mm 250 ...]   (= --top NAME)

``--top`` picks the design (default ``follow_target``; docs/sensor_designs.md describes the
sensor designs, docs/lidar.md the corridor followers), and the Verilog module is named after
it. Every ``FollowTargetParams`` field is an option (``--diff-min 5``, ``--base-dps
0,400,...``; ``follow_target``, ``follow_target_safe`` and ``turret_tracker``'s body camera);
``--preset NAME`` starts from a preset, the other options on top. The sensor designs'
parameters are options too (``fpga_robotics.cli.sensor_options``), and ``--variant NAME``
exports a seeded buggy variant. A bad value, an unknown preset or an option
the top does not read prints what is wrong and exits with code 2.
"""

import os
from dataclasses import fields

from fpga_robotics.cli.board import add_board_arguments, run_board
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.param_options import (
    add_param_arguments,
    design_params_from_items,
    params_from_args,
    refuse_followtarget_options,
)
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.cli.sensor_options import (
    SENSOR_GROUPS,
    add_sensor_arguments,
    given_options,
    sensor_option,
    sensor_params_from_args,
)
from fpga_robotics.designs.reference import is_builtin, resolve_design
from fpga_robotics.flow.export import TOPS, generate_top_verilog
from fpga_robotics.hw.corridor_follow import CorridorFollow
from fpga_robotics.hw.corridor_follow_uart import CorridorFollowUart
from fpga_robotics.hw.follow_line import FollowLine
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.hw.safe_follow import FollowTargetSafe
from fpga_robotics.hw.turret_params import TurretParams
from fpga_robotics.hw.turret_tracker import TurretTracker
from fpga_robotics.hw.variants import VARIANTS, variant_params
from fpga_robotics.hw.verilog import TOP_NAME, generate_verilog
from fpga_robotics.sim.files import check_output_path, check_paths_apart, write_atomic

__all__ = ["build_parser", "main"]


def build_parser(prog="fpga-robotics export"):
    parser = CommandParser(
        prog=prog,
        description="Write a design as one self-contained Verilog file (top module named "
        "after --top).",
    )
    parser.add_argument(
        "--top",
        default=TOP_NAME,
        choices=TOPS,
        help="the design (default %(default)s; docs/sensor_designs.md for the others)",
    )
    parser.add_argument(
        "-o",
        "--output",
        default=None,
        help="output Verilog file (default: build/<top>.v); its directory is "
        "created if missing; with --board: the output directory "
        "(default build/<board>)",
    )
    parser.add_argument(
        "--design",
        metavar="REF",
        help="a design of your own instead of --top: FILE.py:Name or "
        "package.module:Name (docs/your_design.md); the module is named "
        "after Name (a built-in design's name is --top NAME, with its options)",
    )
    parser.add_argument(
        "--param",
        dest="design_params",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a parameter of the --design (repeatable)",
    )
    add_board_arguments(parser)
    add_param_arguments(parser)
    add_sensor_arguments(parser)
    return parser


def main(argv=None, prog="fpga-robotics export"):
    parser = build_parser(prog)
    args = parser.parse_args(argv)  # a bad option: one line, exit 2
    if args.design is not None:
        if (
            args.top != TOP_NAME
            or args.board is not None
            or args.bitstream
            or args.seed is not None
        ):
            raise UsageError(
                "--design exports one design as a Verilog file: --top, --board, --bitstream "
                "and --seed go without it (fpga-robotics board --design REF puts it on a board)"
            )
        if not is_builtin(args.design.strip()):
            return _export_design(args)
        _take_builtin_as_top(args)
    if args.design_params:
        raise UsageError("--param sets a parameter of a --design REF (a design of your own)")
    _check_options_fit_the_top(args)
    params = params_from_args(args) if args.top not in _NO_FOLLOW_TARGET else None
    if args.board is not None:  # a board top instead (fpga_robotics.flow.board)
        out_dir = args.output
        if out_dir is None:
            out_dir = os.path.join("build", args.board)
        return run_board(args, params, out_dir, prog)
    if args.bitstream:
        raise UsageError("--bitstream needs --board NAME (e.g. --board ulx3s-85f)")
    if args.seed is not None:
        raise UsageError("--seed is nextpnr's placement seed: it needs --board NAME --bitstream")
    output = args.output if args.output is not None else os.path.join("build", f"{args.top}.v")
    if os.path.isdir(output):
        raise UsageError(
            f"{output} is a directory; give the Verilog file's path, e.g. "
            f"{os.path.join(output, args.top + '.v')}"
        )
    check_output_path(output, what="Verilog file")
    if args.top == TOP_NAME:
        text, what = generate_verilog(params), _follow_target_text(args, params)
    else:
        text, what = _sensor_top(args, params)
    write_atomic(output, text, what="Verilog file")
    print(f"wrote {output} ({what}, module {args.top})")
    return 0


def _follow_target_text(args, params):
    preset = f", preset {args.preset}" if args.preset is not None else ""
    return f"{params.width}x{params.height}{preset}"


def _sensor_top(args, params):
    """``(Verilog text, description)`` of ``follow_target_safe``, ``follow_line`` or a
    corridor follower."""
    variant = f", variant {args.variant}" if args.variant is not None else ""
    if args.top in ("corridor_follow", "corridor_follow_uart"):
        corridor = sensor_params_from_args(args, "corridor", args.top)
        nearest = sensor_params_from_args(args, "nearest", args.top)
        if args.top == "corridor_follow":
            return generate_top_verilog(CorridorFollow(corridor, nearest), args.top), (
                f"keep {corridor.keep_mm} mm, stop {corridor.stop_mm} mm{variant}"
            )
        uart = sensor_params_from_args(args, "uart", args.top)
        text = generate_top_verilog(CorridorFollowUart(corridor, nearest, uart), args.top)
        return text, (
            f"keep {corridor.keep_mm} mm, stop {corridor.stop_mm} mm, {uart.baud} baud at "
            f"{uart.clock_hz} Hz{variant}"
        )
    if args.top == "turret_tracker":
        turret = _turret_params(args)  # no option sets it: its defaults, or a variant's
        text = generate_top_verilog(TurretTracker(params, turret), args.top)
        return text, (
            f"body camera {_follow_target_text(args, params)}, pan camera "
            f"{turret.width}x{turret.height} on a servo{variant}"
        )
    if args.top == "follow_line":
        line = sensor_params_from_args(args, "line", args.top)
        sensors = f"{line.n_sensors} sensor{'s' if line.n_sensors > 1 else ''}"
        return generate_top_verilog(FollowLine(line), args.top), sensors + variant
    us = sensor_params_from_args(args, "us", args.top)
    interlock = sensor_params_from_args(args, "interlock", args.top)
    text = generate_top_verilog(FollowTargetSafe(params, us, interlock), args.top)
    return text, (
        f"{_follow_target_text(args, params)}, {us.clock_hz} Hz, stop "
        f"{interlock.stop_mm} mm, resume {interlock.resume_mm} mm{variant}"
    )


def _turret_params(args):
    """The turret channel's parameters: the defaults, or a seeded bug of ``turret_tracker``."""

    if args.variant is None:
        return TurretParams()
    if args.variant not in VARIANTS or VARIANTS[args.variant].design != args.top:
        names = [n for n, v in VARIANTS.items() if v.design == args.top]
        raise UsageError(
            f"--variant {args.variant!r} is no variant of --top {args.top}; known variants: "
            f"{', '.join(names)}"
        )
    return variant_params(args.variant)


def _check_options_fit_the_top(args):
    """A parameter the chosen top does not read is a usage error, not silently ignored."""
    for key, (_, _, _, tops) in SENSOR_GROUPS.items():
        given = given_options(args, key)
        if given and args.top not in tops:
            raise UsageError(
                f"{', '.join(given)} applies to --top {' or '.join(tops)}, not to --top {args.top}"
            )
    if args.variant is not None and args.top == TOP_NAME:
        if args.variant not in VARIANTS:
            raise UsageError(
                f"unknown --variant {args.variant!r}; known variants: {', '.join(VARIANTS)}"
            )
        top = VARIANTS[args.variant].design
        raise UsageError(
            f"--variant {args.variant} is a seeded bug of --top {top}: it needs --top {top}"
        )
    if args.top != TOP_NAME and args.board is not None:
        raise UsageError(
            f"--board exports the follow_target board top; it cannot be combined "
            f"with --top {args.top}"
        )
    if args.top in _NO_FOLLOW_TARGET:
        # These read no FollowTargetParams: any of those options is a mistake.
        ft_given = [
            name
            for name, value in vars(args).items()
            if value is not None and _is_follow_target_option(name)
        ]
        if ft_given:
            options = ", ".join("--" + n.replace("_", "-") for n in ft_given)
            tops = [top for top in TOPS if top not in _NO_FOLLOW_TARGET]
            raise UsageError(
                f"{options} applies to --top {', '.join(tops[:-1])} or {tops[-1]} (its body "
                f"camera's channel), not to --top {args.top}"
            )


#: The tops that take no FollowTargetParams (turret_tracker takes them for its body camera).
_NO_FOLLOW_TARGET = ("follow_line", "corridor_follow", "corridor_follow_uart")


def _is_follow_target_option(dest):
    return dest == "preset" or dest in {f.name for f in fields(FollowTargetParams) if f.init}


def _take_builtin_as_top(args):
    """``--design NAME`` of a built-in design is ``--top NAME``, with that top's options."""
    name = args.design.strip()
    if args.design_params:
        params = [item.partition("=") for item in args.design_params]
        options = [(_option_for(name, key.strip()), key, value) for key, _, value in params]
        unknown = [key for option, key, _ in options if option is None]
        if unknown:
            raise UsageError(
                f"--param sets a parameter of a design of your own; the built-in design {name} "
                f"has no option for {', '.join(unknown)} (fpga-robotics export --help)"
            )
        raise UsageError(
            f"--param sets a parameter of a design of your own; the built-in design {name} "
            f"takes its own options instead: {' '.join(f'{o} {v}' for o, _, v in options)}"
        )
    args.top, args.design = name, None


def _option_for(top, name):
    """The option that sets parameter ``name`` of the built-in ``top`` (None if none does)."""
    if top not in _NO_FOLLOW_TARGET and _is_follow_target_option(name):
        return "--" + name.replace("_", "-")
    return sensor_option(top, name)


def _export_design(args):
    """``--design REF``: any Amaranth design of one's own as Verilog, its module named after
    the class or function the reference names; its other options must not be given."""
    if args.design.strip().startswith("verilog:"):  # said before its port map is asked for
        raise UsageError(f"--design {args.design} is Verilog already: nothing to export")
    # Options of the built-in tops would be silently ignored: refused, as mutate does.
    refuse_followtarget_options(args, "--design REF exports a design of your own")
    for key, (_, _, _, tops) in SENSOR_GROUPS.items():
        given = given_options(args, key)
        if given:
            raise UsageError(
                f"{', '.join(given)} applies to --top {' or '.join(tops)}, not to --design REF "
                "(give its parameters as --param NAME=VALUE)"
            )
    if args.variant is not None:
        raise UsageError("--variant names a seeded bug of a built-in top: it goes without --design")
    spec = resolve_design(
        args.design, design_params_from_items(args.design_params), option="--param"
    )
    name = spec.reference.rpartition(":")[2]
    output = args.output if args.output is not None else os.path.join("build", f"{name}.v")
    # Verilog written over the design's file, or a module it imports beside it, would lose it.
    files = spec.source_files()
    labels = ["--design", *["--design's module"] * (len(files) - 1)]
    check_paths_apart([("-o", output)], list(zip(labels, files, strict=False)))
    if os.path.isdir(output):
        raise UsageError(
            f"{output} is a directory; give the Verilog file's path, e.g. "
            f"{os.path.join(output, name + '.v')}"
        )
    check_output_path(output, what="Verilog file")
    text = generate_top_verilog(spec.build(), name)
    write_atomic(output, text, what="Verilog file")
    print(f"wrote {output} (module {name}, {len(spec.ports)} ports)")
    return 0


if __name__ == "__main__":  # python -m fpga_robotics.cli.export: as fpga-robotics export
    from fpga_robotics.cli import run_command

    run_command("export")
