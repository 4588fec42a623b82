"""The design's parameters as command-line options, shared by ``export``, ``board`` and the
benchmarks: one option per ``FollowTargetParams`` field (``--diff-min 5``,
``--base-dps 0,400,...``)."""

import argparse
from dataclasses import fields

from .errors import UsageError
from .hw.params import FollowTargetParams

__all__ = ["add_param_arguments", "params_from_args"]

#: Parameters given as a comma-separated list of ints on the command line.
_TUPLE_PARAMS = ("proximity_thresholds", "base_dps")


def _int_list(text):
    try:
        return tuple(int(v, 0) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated integers such as 0,400,300, got {text!r}"
        ) from None


def add_param_arguments(parser):
    """Add one option per ``FollowTargetParams`` field (default: the contract's default)."""
    group = parser.add_argument_group("design parameters (defaults: the contract's, docs/contract.md)")
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
