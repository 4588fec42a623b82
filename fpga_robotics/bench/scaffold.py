"""What every benchmark shares: its command line, its clocks and medians, its output.

A subject module declares its own options and its measurement, and gets the rest here::

    main = command(run, __doc__, name="camera", options=add_options, repeats=5, frames=60)

``command`` builds ``main(argv, prog)``: the common options (``--repeats``, ``--frames``,
``--min-seconds`` where the subject takes them, ``--json PATH`` always, ``--calibrate`` where
its figures hold times), their checks, and bad arguments as ``UsageError`` (one line
``prog: error: ...``, exit 2, from ``run_cli``). ``run(args)`` prints its figures as it measures and returns them as a dict;
``--json`` writes that dict atomically with the machine's description, and ``--calibrate``
times the calibration design in the same run and prints every absolute time of the dict
(a key that names milliseconds: ``frame_ms``, ``ms_per_frame``) as a multiple of it: the
figure that travels between machines.
"""

import argparse
import math
import os
import platform
import re
from dataclasses import asdict

from fpga_robotics.bench.calibration import measure_calibration
from fpga_robotics.bench.timing import Spread, Times, gc_paused, stopwatch  # noqa: F401 (the scaffold's names)
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.sim.backends import BackendError
from fpga_robotics.sim.backends.toolchain import find_compiler
from fpga_robotics.sim.camera.raster import VERTICAL_MARGIN, max_hfov
from fpga_robotics.sim.files import check_output_path, write_json_atomic

__all__ = [
    "BenchParser",
    "Spread",
    "add_follow_target_design",
    "check_follow_target_design",
    "check_follow_target_scenario",
    "check_json_path",
    "check_not_given",
    "command",
    "figure_against",
    "gc_paused",
    "parse_size",
    "parse_sizes",
    "print_table",
    "ratios_to",
    "stopwatch",
    "write_json",
]

#: Largest width or height a benchmark takes (the design's own limit).
MAX_SIDE = 4096
MAX_REPEATS = 1000
MAX_FRAMES = 10**6


class BenchParser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors are ``UsageError``: one line, exit code 2."""

    def error(self, message):
        raise UsageError(message)


def parse_size(text, what="a size"):
    """``"160x120"`` -> ``(160, 120)``; ``UsageError`` for anything else."""
    try:
        w, h = (int(v) for v in text.strip().lower().split("x"))
    except ValueError:
        raise UsageError(f"{what} is WIDTHxHEIGHT, e.g. 160x120; got {text!r}") from None
    if not (1 <= w <= MAX_SIDE and 1 <= h <= MAX_SIDE):
        raise UsageError(f"{what} needs a width and height of 1..{MAX_SIDE}, got {text!r}")
    return w, h


def parse_sizes(text, what="a size", *, hfov=None):
    """``"160x120,640x480"`` -> ``[(160, 120), (640, 480)]``. With ``hfov`` (rad, the
    camera's that renders them) also refuses a size so tall that its top and bottom rows
    would look straight up or down (``sim.camera.max_hfov``), which the renderer refuses."""
    sizes = [parse_size(item, what) for item in text.split(",") if item.strip()]
    if not sizes:
        raise UsageError(f"{what} list is empty; write WIDTHxHEIGHT[,WIDTHxHEIGHT...]")
    for w, h in sizes:
        if hfov is not None and max_hfov(w, h) < hfov:
            tallest = math.tan(math.pi / 2 - VERTICAL_MARGIN) / math.tan(hfov / 2)
            raise UsageError(
                f"{what} {w}x{h} is too tall for the camera's hfov {hfov:g} rad: the renderer "
                f"draws at most {max_hfov(w, h):.4f} rad at that size (the top and bottom rows "
                f"would look straight up or down); keep the height at most "
                f"{math.floor(tallest * 10) / 10:g} times the width"
            )
    return sizes


def print_table(header, rows, *, first_width=None):
    """Columns right-aligned to the widest cell, the first left-aligned; cells as given
    (format numbers before)."""
    rows = [[str(c) for c in row] for row in rows]
    widths = [max(len(str(h)), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    if first_width:
        widths[0] = max(widths[0], first_width)

    def line(cells):
        return "  ".join(
            f"{c:<{widths[0]}}" if i == 0 else f"{c:>{widths[i]}}" for i, c in enumerate(cells)
        ).rstrip()

    print(line(header))
    for row in rows:
        print(line(row), flush=True)


def add_follow_target_design(parser):
    """``--design``: of a subject that times FollowTarget only (its frame path or its pins);
    a design of one's own is timed by ``bench user_verilog --design``."""
    parser.add_argument(
        "--design",
        metavar="REF",
        default="follow_target",
        help="follow_target (the only one here; a design of your own: "
        "bench user_verilog --design REF)",
    )


def check_follow_target_design(args, subject):
    """One line when ``--design`` names a design this subject cannot time."""
    if args.design != "follow_target":
        raise UsageError(
            f"bench {subject} times follow_target only (its frame path and its own world); "
            f"a design of your own ({args.design}) is timed by fpga-robotics bench "
            f"user_verilog --design REF (--ports MAP for verilog:FILES)"
        )


def check_follow_target_scenario(scenario, subject):
    """One line when ``scenario`` runs anything but FollowTarget in compressed timing: this
    subject builds FollowTarget's frame models, whatever the scenario's design is."""
    own_design = scenario.top != "follow_target" or scenario.foreign is not None
    if not own_design and scenario.sim.timing == "compressed":
        return
    design = "its own Verilog design" if scenario.foreign is not None else scenario.top
    raise UsageError(
        f"bench {subject} times follow_target in compressed timing only; scenario "
        f"{scenario.name!r} runs {design} in {scenario.sim.timing} timing (other designs "
        f"are timed by fpga-robotics bench user_verilog --design REF --scenario NAME)"
    )


def figure_against(value, limit, decimals):
    """``value`` with ``decimals`` decimals, or as many more as it takes for the printed figure
    to sit on the same side of ``limit`` as ``value`` (4.498 against 4.5 prints 4.498, not
    4.50: a target line must not show a figure on the limit and call it missed)."""

    def side(x):
        return (x > limit) - (x < limit)

    text = f"{value:.{decimals}f}"
    while side(float(text)) != side(value) and decimals < 15:
        decimals += 1
        text = f"{value:.{decimals}f}"
    return text


def check_json_path(path):
    """Checked before measuring, not after minutes of it."""
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise UsageError(f"cannot write {path}: no directory {directory}")
    return check_output_path(path, what="--json")


def machine():
    """What the figures were measured on."""
    try:
        compiler = find_compiler().version
    except BackendError:
        compiler = None
    return {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "cpus": os.cpu_count(),
        "load_average": os.getloadavg()[0],
        "compiler": compiler,
    }


def _plain(value):
    """JSON-ready: dataclasses (``Spread``) as dicts, tuples as lists, recursively."""
    if isinstance(value, Spread):
        return asdict(value)
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def write_json(path, prog, figures, calibration=None):
    """``figures`` (and the calibration, if measured) with the machine, written atomically."""
    data = {"command": prog, "machine": machine(), "figures": _plain(figures)}
    if calibration is not None:
        data["calibration"] = _plain(calibration)
    write_json_atomic(path, data, what="--json")


_MS_KEY = re.compile(r"(^|_)ms(_|$)")


def _label(item, index):
    """A list entry's name: its backend, design, mode and size where it has them."""
    parts = [
        str(item[k])
        for k in ("backend", "design", "mode", "world", "size")
        if isinstance(item, dict) and k in item
    ]
    if isinstance(item, dict) and "width" in item and "height" in item:
        parts.append(f"{item['width']}x{item['height']}")
    return " ".join(parts) or str(index)


def absolute_times(figures, prefix="", in_ms=False):
    """``(name, ms)`` of every entry whose key says milliseconds (``frame_ms``,
    ``ms_per_frame``, or every number under a ``steps_ms`` dict); nested dicts and lists
    walked, a ``Spread`` by its median."""
    out = []
    items = (
        figures.items()
        if isinstance(figures, dict)
        else ((_label(v, i), v) for i, v in enumerate(figures))
    )
    for key, value in items:
        name = f"{prefix}{key}"
        is_ms = in_ms or bool(_MS_KEY.search(str(key)))
        if isinstance(value, (dict, list, tuple)):
            out += absolute_times(value, f"{name}.", is_ms and isinstance(value, dict))
        elif is_ms and isinstance(value, (int, float, Spread)) and not isinstance(value, bool):
            out.append((name, value.median if isinstance(value, Spread) else float(value)))
    return out


def ratios_to(figures, reference_ms, cpu_reference_ms=None):
    """Every absolute time of ``figures`` as a multiple of ``reference_ms``; a CPU time (its
    name says ``cpu``) of ``cpu_reference_ms`` where given, so that like meets like."""
    cpu_ref = cpu_reference_ms or reference_ms
    return [
        (name, ms, ms / (cpu_ref if "cpu" in name else reference_ms))
        for name, ms in absolute_times(figures)
    ]


def _add_common(parser, repeats, frames, min_seconds, calibrate):
    if repeats is not None:
        parser.add_argument(
            "--repeats",
            type=int,
            default=repeats,
            help=f"repeats of each measurement (default {repeats})",
        )
    if frames is not None:
        parser.add_argument(
            "--frames", type=int, default=frames, help=f"frames per measurement (default {frames})"
        )
    if min_seconds is not None:
        parser.add_argument(
            "--min-seconds",
            type=float,
            default=min_seconds,
            help=f"repeat the frames until each case has run this long (default {min_seconds:g})",
        )
    parser.add_argument("--json", metavar="PATH", help="also write the figures to PATH")
    if calibrate:
        parser.add_argument(
            "--calibrate",
            action="store_true",
            help="also time the calibration design (bench calibrate) in this run "
            "and print every time as a multiple of it",
        )
    else:
        parser.set_defaults(calibrate=False)


def _check_common(args):
    if getattr(args, "repeats", None) is not None and not 1 <= args.repeats <= MAX_REPEATS:
        raise UsageError(f"--repeats must be 1..{MAX_REPEATS}, got {args.repeats}")
    if getattr(args, "frames", None) is not None and not 1 <= args.frames <= MAX_FRAMES:
        raise UsageError(f"--frames must be 1..{MAX_FRAMES}, got {args.frames}")
    seconds = getattr(args, "min_seconds", None)
    if seconds is not None and not (math.isfinite(seconds) and 0 <= seconds <= 3600):
        raise UsageError(f"--min-seconds must be a finite number in 0..3600, got {seconds}")
    if args.json is not None:
        check_json_path(args.json)


def _given(parser, argv):
    """The destinations of the options ``argv`` gives (not left at their defaults)."""
    defaults = [(action, action.default) for action in parser._actions]
    try:
        for action, _ in defaults:
            action.default = argparse.SUPPRESS
        return frozenset(vars(parser.parse_args(argv)))
    finally:
        for action, default in defaults:
            action.default = default


def check_not_given(args, dests, reason):
    """One line when the command line gives any of the options ``dests``: they cannot
    apply, for ``reason`` ("with --figures DIR (...)"), and are refused, not ignored."""
    given = [dest for dest in dests if dest in args.given]
    if given:
        raise UsageError(f"--{given[0].replace('_', '-')} does not apply {reason}")


def command(
    run,
    doc,
    *,
    name,
    options=None,
    repeats=None,
    frames=None,
    min_seconds=None,
    check=None,
    calibrate=True,
):
    """``main(argv=None, prog=...)`` of a benchmark: parse (common options, then the
    subject's ``options(parser)``; ``args.given`` the options the command line gives),
    check (common, then ``check(args)``), ``run(args)`` -> figures, then the calibration and
    ``--json`` if asked for. ``calibrate=False``: figures with no times, no ``--calibrate``."""
    description = doc.strip().split("\n\n")[0].replace("``", "")  # no RST in --help

    def main(argv=None, prog=f"fpga-robotics bench {name}"):
        parser = BenchParser(prog=prog, description=description)
        if options is not None:
            options(parser)
        _add_common(parser, repeats, frames, min_seconds, calibrate)
        args = parser.parse_args(argv)
        args.given = _given(parser, argv)
        _check_common(args)
        if check is not None:
            check(args)
        figures = run(args)
        calibration = None
        if args.calibrate and figures:
            # At least 3 passes, so that its range means something.
            calibration = measure_calibration(repeats=max(3, getattr(args, "repeats", 5) or 5))
            print_calibrated(figures, calibration)
        if args.json is not None:
            write_json(args.json, prog, figures or {}, calibration)
            print(f"figures written to {args.json}")
        return 0

    main.__doc__ = doc
    return main


def print_calibrated(figures, calibration):
    """Each absolute time of ``figures`` next to the same run's calibration frame time."""
    ref, cpu_ref = calibration["frame_ms"].median, calibration["cpu_ms"].median
    rows = [
        (name, f"{ms:.4g} ms", f"{ratio:.3g}x")
        for name, ms, ratio in ratios_to(figures, ref, cpu_ref)
    ]
    in_frames = "; the times above in calibration frames (CPU times in its CPU time):"
    print(
        f"calibration ({calibration['what']}): {calibration['frame_ms']:.4f} ms/frame, "
        f"CPU {calibration['cpu_ms']:.4f} (median, min-max of {calibration['frame_ms'].n})"
        f"{in_frames if rows else ''}"
    )
    if rows:
        print_table(("figure", "time", "x calibration"), rows)
