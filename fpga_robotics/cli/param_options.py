"""The design's parameters as command-line options, shared by ``export``, ``board`` and the
benchmarks: ``--preset NAME`` and one option per ``FollowTargetParams`` field
(``--diff-min 5``, ``--base-dps 0,400,...``, ``--found-rule gt``)."""

import argparse
import tomllib
from dataclasses import fields

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.hw.params import CHOICES, PRESETS, FollowTargetParams

__all__ = [
    "add_define_argument",
    "add_design_param_argument",
    "add_param_arguments",
    "defines_from_items",
    "design_params_from_items",
    "params_from_args",
    "refuse_followtarget_options",
]

#: Parameters given as a comma-separated list of ints on the command line.
_TUPLE_PARAMS = ("proximity_thresholds", "base_dps", "steer_dps")


def _int_list(text):
    try:
        return tuple(int(v, 0) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated integers such as 0,400,300, got {text!r}"
        ) from None


def add_param_arguments(parser):
    """Add ``--preset`` and one option per ``FollowTargetParams`` field (default: the
    contract's default, or the preset's value)."""
    group = parser.add_argument_group(
        "design parameters (defaults: the contract's, docs/contract.md; with --preset the "
        "preset's, the other options on top)"
    )
    # Checked in params_from_args, not by argparse: an unknown name is one line, exit 2.
    group.add_argument(
        "--preset",
        default=None,
        metavar="NAME",
        help=f"start from a preset: {', '.join(PRESETS)} ({'; '.join(PRESETS.values())})",
    )
    for f in fields(FollowTargetParams):
        if not f.init:
            continue
        option = "--" + f.name.replace("_", "-")
        if f.name in _TUPLE_PARAMS:
            group.add_argument(
                option,
                type=_int_list,
                default=None,
                metavar="A,B,...",
                help=f"{f.name} as comma-separated ints",
            )
        elif f.name in CHOICES:
            group.add_argument(
                option,
                default=None,
                metavar="{" + ",".join(CHOICES[f.name]) + "}",
                help=f"{f.name} (default {f.default})",
            )
        else:
            group.add_argument(
                option,
                type=int,
                default=None,
                metavar="N",
                help=f"{f.name} (default {_default_text(f)})",
            )


def add_design_param_argument(parser):
    """``--param NAME=VALUE`` (repeatable): a parameter of the ``--design`` of one's own."""
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="with --design: one of its parameters (a TOML value; repeatable)",
    )


def add_define_argument(parser):
    """``--define NAME[=VALUE]`` (repeatable): a `define macro of a Verilog ``--design``."""
    parser.add_argument(
        "--define",
        action="append",
        default=[],
        metavar="NAME[=VALUE]",
        help="with --design verilog:...: a `define macro read before its files (repeatable)",
    )


def design_params_from_items(items, option="--param"):
    """``--param NAME=VALUE`` items as a dict (values read as TOML, else as text). A name
    given twice is a ``UsageError``: which value would the design get?"""
    params = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name.isidentifier():
            raise UsageError(f"{option} must be NAME=VALUE, got {item!r}")
        if name in params:
            raise UsageError(f"{option} {name} is given twice; give each parameter once")
        try:
            params[name] = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            params[name] = text.strip()
    return params


def defines_from_items(items):
    """``--define NAME[=VALUE]`` items (a Verilog design's `define macros) as a dict, values
    read as ``--param``'s; a name alone is ``True``: defined, without a value."""
    defines = {}
    for item in items:
        name, sep, _ = item.partition("=")
        name = name.strip()
        if not name.isidentifier():
            raise UsageError(f"--define must be NAME or NAME=VALUE, got {item!r}")
        if name in defines:
            raise UsageError(f"--define {name} is given twice; give each macro once")
        defines[name] = design_params_from_items([item], option="--define")[name] if sep else True
    return defines


def _default_text(f):
    if f.name == "sx_bits":
        return "the full width, wide enough for any frame"
    if f.default is None:
        return "derived from the geometry"
    return str(f.default)


def params_from_args(args):
    """``FollowTargetParams`` from parsed options (the preset first, the other options on
    top); a bad value or an unknown preset raises ``UsageError``."""
    given = {}
    for f in fields(FollowTargetParams):
        if f.init and getattr(args, f.name, None) is not None:
            given[f.name] = getattr(args, f.name)
    preset = getattr(args, "preset", None)
    if preset is not None and preset not in PRESETS:
        raise UsageError(f"unknown --preset {preset!r}; known presets: {', '.join(PRESETS)}")
    try:
        if preset is not None:
            return FollowTargetParams.preset(preset, **given)
        return FollowTargetParams(**given)
    except (ValueError, TypeError) as exc:
        raise UsageError(f"bad design parameter: {exc}") from None


def given_followtarget_options(args):
    """The FollowTarget options given (``--preset``, its parameters, ``--against`` where the
    command has it), as typed: ``["--preset", "--kp-num"]``."""
    given = [name for name in ("preset", "against") if getattr(args, name, None) is not None]
    given += [f.name for f in fields(FollowTargetParams) if getattr(args, f.name, None) is not None]
    return ["--" + name.replace("_", "-") for name in given]


def refuse_followtarget_options(args, consequence):
    """``UsageError`` naming the FollowTarget options given: with ``--design REF`` they would
    be silently ignored; ``consequence`` says what the command does instead."""
    given = given_followtarget_options(args)
    if given:
        options = ", ".join(given)
        raise UsageError(
            f"{options}: FollowTarget's options; {consequence} (give its parameters as "
            "--param NAME=VALUE)"
        )
