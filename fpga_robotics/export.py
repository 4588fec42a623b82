"""Export ``FollowTarget`` as one self-contained Verilog file.

    python -m fpga_robotics.export -o build/follow_target.v [--width 320 --height 240 ...]
    python -m fpga_robotics.export --board ulx3s-85f -o DIR [--bitstream]   (board top + LPF)

Every ``FollowTargetParams`` field is an option (``--diff-min 5``, ``--base-dps 0,400,...``);
a bad value prints what is wrong and exits with code 2.
"""

import argparse
import os
import tempfile
from dataclasses import fields

from amaranth.back import verilog
from amaranth.hdl import Const, Value, ValueCastable
from amaranth.lib import wiring

from .board_build import add_board_arguments, run_board
from .errors import UsageError, run_cli
from .hw.params import FollowTargetParams
from .hw.top import FollowTarget

__all__ = [
    "TOP_NAME",
    "build_parser",
    "generate_verilog",
    "main",
    "params_from_args",
    "verilog_ports",
    "write_atomically",
]

#: Name of the Verilog module.
TOP_NAME = "follow_target"

#: Parameters given as a comma-separated list of ints on the command line.
_TUPLE_PARAMS = ("proximity_thresholds", "base_dps")


def verilog_ports(top):
    """``{name: (value, "i"|"o")}``: the ports of a component, named ``member__sub`` as
    Amaranth names them, leaving out constant members (``ready`` of non-stallable streams,
    which ``verilog.convert`` would otherwise reject)."""
    ports = {}
    for path, member, value in top.signature.flatten(top):
        if isinstance(value, ValueCastable):
            value = value.as_value()
        value = Value.cast(value)
        if isinstance(value, Const):
            continue
        direction = "i" if member.flow == wiring.In else "o"
        ports["__".join(map(str, path))] = (value, direction)
    return ports


def generate_verilog(params=None):
    """Return the Verilog text of ``FollowTarget(params)``, top module ``follow_target``.

    Ports: ``clk rst pixels__valid pixels__payload color_sel filtered__valid filtered__payload
    frame_done found proximity centroid_x centroid_leds motor_left motor_right``.
    """
    params = FollowTargetParams() if params is None else params
    top = FollowTarget(params)
    # Direction None: Amaranth infers it (driven inside the design = output).
    ports = {name: (value, None) for name, (value, _) in verilog_ports(top).items()}
    return verilog.convert(top, name=TOP_NAME, ports=ports, emit_src=False)


def write_atomically(path, text):
    """Write ``text`` to ``path`` via a temporary file in the same directory and a rename, so
    an interrupted run never leaves a half-written file. Creates missing directories."""
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=os.path.basename(path), dir=directory)
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.chmod(tmp, default_file_mode())  # mkstemp makes it private (0600)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def default_file_mode():
    """The mode a newly created file gets here (0666 minus the umask)."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _int_list(text):
    try:
        return tuple(int(v, 0) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated integers such as 0,400,300, got {text!r}"
        ) from None


def add_param_arguments(parser):
    """Add one option per ``FollowTargetParams`` field (default: the contract's default)."""
    group = parser.add_argument_group("design parameters (defaults: hw-spec values)")
    for f in fields(FollowTargetParams):
        if not f.init:
            continue
        option = "--" + f.name.replace("_", "-")
        if f.name in _TUPLE_PARAMS:
            group.add_argument(option, type=_int_list, default=None, metavar="A,B,...",
                               help=f"{f.name} as comma-separated ints")
        else:
            group.add_argument(option, type=int, default=None, metavar="N",
                               help=f"{f.name} (default {_default_text(f)})")


def _default_text(f):
    if f.default is None:
        return "derived from the geometry"
    return str(f.default)


def params_from_args(args):
    """``FollowTargetParams`` from parsed options; a bad value raises ``UsageError``."""
    given = {}
    for f in fields(FollowTargetParams):
        if f.init and getattr(args, f.name, None) is not None:
            given[f.name] = getattr(args, f.name)
    try:
        return FollowTargetParams(**given)
    except (ValueError, TypeError) as exc:
        raise UsageError(f"bad design parameter: {exc}") from None


def build_parser():
    parser = argparse.ArgumentParser(
        prog="python -m fpga_robotics.export",
        description="Write the FollowTarget design as one self-contained Verilog file "
                    f"(top module {TOP_NAME}).",
    )
    parser.add_argument("-o", "--output", default=os.path.join("build", f"{TOP_NAME}.v"),
                        help="output Verilog file (default: %(default)s); its directory is "
                             "created if missing; with --board: the output directory "
                             "(default build/<board>)")
    add_board_arguments(parser)
    add_param_arguments(parser)
    return parser


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)  # a bad option: argparse's message and exit code 2
    params = params_from_args(args)
    if args.board is not None:  # a board top instead (fpga_robotics.board_build)
        out_dir = args.output
        if out_dir == parser.get_default("output"):
            out_dir = os.path.join("build", args.board)
        return run_board(args, params, out_dir)
    if args.bitstream:
        raise UsageError("--bitstream needs --board NAME (e.g. --board ulx3s-85f)")
    if os.path.isdir(args.output):
        raise UsageError(
            f"{args.output} is a directory; give the Verilog file's path, e.g. "
            f"{os.path.join(args.output, TOP_NAME + '.v')}"
        )
    text = generate_verilog(params)
    try:
        write_atomically(args.output, text)
    except OSError as exc:
        raise UsageError(f"cannot write {args.output}: {exc.strerror or exc}") from None
    print(f"wrote {args.output} ({params.width}x{params.height}, module {TOP_NAME})")
    return 0


if __name__ == "__main__":
    run_cli(main, prog="python -m fpga_robotics.export")
