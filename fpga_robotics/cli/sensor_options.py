"""The sensor designs' parameters as command-line options (``export --top ...``): one option
per field of ``UltrasoundParams`` (``--us-period-us 60000``), ``InterlockParams``
(``--stop-mm 300``) and ``FollowLineParams`` (``--line-base-dps 250``), and ``--variant NAME``
for a seeded buggy variant (``hw/variants.py``)."""

from dataclasses import MISSING, fields

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.hw.lidar_params import CorridorParams, NearestParams, UartParams
from fpga_robotics.hw.sensor_params import (
    EDGE_SIDES,
    FollowLineParams,
    InterlockParams,
    UltrasoundParams,
)
from fpga_robotics.hw.variants import VARIANTS, variant_params

__all__ = [
    "SENSOR_GROUPS",
    "add_sensor_arguments",
    "given_options",
    "sensor_option",
    "sensor_params_from_args",
]

_CORRIDOR_TOPS = ("corridor_follow", "corridor_follow_uart")

#: key -> (params class, option prefix, heading, the tops that read it). Boolean fields are
#: no options: the seeded variants that flip them are named by ``--variant``.
SENSOR_GROUPS = {
    "us": (UltrasoundParams, "us-", "HC-SR04 ultrasound driver", ("follow_target_safe",)),
    "interlock": (InterlockParams, "", "obstacle interlock", ("follow_target_safe",)),
    "line": (FollowLineParams, "line-", "line follower", ("follow_line",)),
    "corridor": (CorridorParams, "corridor-", "corridor follower", _CORRIDOR_TOPS),
    "nearest": (NearestParams, "nearest-", "LIDAR nearest obstacle", _CORRIDOR_TOPS),
    "uart": (UartParams, "uart-", "LIDAR serial link", ("corridor_follow_uart",)),
}

_CHOICES = {"edge_side": EDGE_SIDES}


def _option_fields(cls):
    return [f for f in fields(cls) if f.default is MISSING or not isinstance(f.default, bool)]


def _dest(key, name):
    return f"{key}__{name}"


def _option(prefix, name):
    return "--" + prefix + name.replace("_", "-")


def add_sensor_arguments(parser):
    """One option per parameter of the sensor designs, and ``--variant``."""
    for key, (cls, prefix, heading, tops) in SENSOR_GROUPS.items():
        group = parser.add_argument_group(f"{heading} parameters (--top {', '.join(tops)})")
        for f in _option_fields(cls):
            default = "derived" if f.default is None else f.default
            if f.name in _CHOICES:
                group.add_argument(
                    _option(prefix, f.name),
                    dest=_dest(key, f.name),
                    default=None,
                    choices=_CHOICES[f.name],
                    help=f"{f.name} (default {default})",
                )
            else:
                group.add_argument(
                    _option(prefix, f.name),
                    dest=_dest(key, f.name),
                    type=int,
                    default=None,
                    metavar="N",
                    help=f"{f.name} (default {default})",
                )
    parser.add_argument(
        "--variant",
        default=None,
        metavar="NAME",
        help="a seeded buggy variant of the top: "
        + "; ".join(f"{v.name} (--top {v.design}: {v.bug})" for v in VARIANTS.values()),
    )


def sensor_option(top, name):
    """The option that sets parameter ``name`` of the sensor design ``top`` (None if none
    does): ``sensor_option("follow_target_safe", "stop_mm")`` is ``"--stop-mm"``."""
    for cls, prefix, _, tops in SENSOR_GROUPS.values():
        if top in tops and name in {f.name for f in _option_fields(cls)}:
            return _option(prefix, name)
    return None


def given_options(args, key):
    """The options of group ``key`` given on the command line, as ``{option: value}``."""
    cls, prefix, _, _ = SENSOR_GROUPS[key]
    return {
        _option(prefix, f.name): getattr(args, _dest(key, f.name))
        for f in _option_fields(cls)
        if getattr(args, _dest(key, f.name)) is not None
    }


def sensor_params_from_args(args, key, top):
    """The params of group ``key`` from the options (with ``--variant`` applied when it
    changes this class); a bad value, or a variant of another top, raises ``UsageError``."""
    cls, _, heading, _ = SENSOR_GROUPS[key]
    values = {
        f.name: getattr(args, _dest(key, f.name))
        for f in _option_fields(cls)
        if getattr(args, _dest(key, f.name)) is not None
    }
    try:
        params = cls(**values)
    except (TypeError, ValueError) as exc:
        raise UsageError(f"bad {heading} parameter: {exc}") from None
    if args.variant is not None:
        if args.variant not in VARIANTS:
            raise UsageError(
                f"unknown --variant {args.variant!r}; known variants: {', '.join(VARIANTS)}"
            )
        variant = VARIANTS[args.variant]
        if variant.design != top:
            raise UsageError(
                f"--variant {args.variant} is a variant of --top {variant.design}, "
                f"not of --top {top}"
            )
        if variant.params_type is cls:
            try:
                params = variant_params(args.variant, params)
            except (TypeError, ValueError) as exc:
                raise UsageError(f"--variant {args.variant}: {exc}") from None
    return params
