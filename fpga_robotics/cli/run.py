"""``fpga-robotics run`` (or ``python -m fpga_robotics.run``): run a scenario in closed loop (or the design on real frames).

Headless and faster than real time by default; prints a progress bar on stderr and a human
summary at the end; ``--summary PATH`` writes the same as JSON. Exit status: 0 when the
scenario's checks pass, 1 when one fails or none could judge the run (verdict n/a), 2 for a
usage error (bad argument, unknown scenario or key, malformed file, unopenable source, missing
simulator).
"""

import contextlib
import copy
import dataclasses
import json
import sys
import time
import tomllib
from importlib import resources
from pathlib import Path

from fpga_robotics.checks.summary import format_summary
from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.cli.param_options import defines_from_items, design_params_from_items
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.designs.reference import design_parameters, design_source_files
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.loop.bindings import check_bindings, scenario_top
from fpga_robotics.loop.compressed import make_backend
from fpga_robotics.loop.continuation import continuation_summary, run_continued
from fpga_robotics.loop.pin_frames import PinFrames, check_frame_backend
from fpga_robotics.loop.pin_shadow import is_design_reference
from fpga_robotics.loop.real_clock import format_extra_outputs, make_pin_backend
from fpga_robotics.loop.shadow import format_shadow, shadow_overrides
from fpga_robotics.loop.sources import open_source, run_source
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.loop.video_out import CameraVideo, VideoPathError, check_video_path
from fpga_robotics.ros.run_options import RosOutputs, add_ros_arguments
from fpga_robotics.scenario.errors import ScenarioError
from fpga_robotics.scenario.load import (
    MAX_SEED,
    ForeignDesignFiles,
    load_scenario,
    parse_resolution,
    shipped_scenarios,
)
from fpga_robotics.scenario.sanity import report_warnings
from fpga_robotics.sim.backends import BACKEND_NAMES
from fpga_robotics.sim.backends.base import BackendError
from fpga_robotics.sim.backends.foreign_choice import FOREIGN_BACKENDS, open_foreign_frames
from fpga_robotics.sim.backends.port_map import load_port_map
from fpga_robotics.sim.camera.render3d.renderer import Render3DUnavailable, load_mujoco
from fpga_robotics.sim.files import check_output_path, check_paths_apart, write_json_atomic
from fpga_robotics.sim.pins import DesignError, PinError, ShadowDesignError
from fpga_robotics.sim.world.config import parse_world_config

__all__ = ["TARGET_CLOTHING", "PortMapUnpaired", "Progress", "build_parser", "main"]

#: Clothing (shirt and trousers, linear RGB 0..1) that each colour select picks out clearly
#: under the shipped scenarios' lighting: one channel group well above the others.
TARGET_CLOTHING = {
    "red": (0.85, 0.1, 0.1),
    "green": (0.1, 0.75, 0.12),
    "blue": (0.1, 0.15, 0.85),
    "yellow": (0.85, 0.8, 0.1),
    "magenta": (0.8, 0.1, 0.8),
    "cyan": (0.1, 0.75, 0.8),
}


#: The scenario ``run`` runs without ``--scenario``.
DEFAULT_SCENARIO = "follow_person"


def _scenario_default(section, key):
    """The default scenario's ``[section] key`` as ``--help`` shows it (read from its TOML
    file, not loaded: ``--help`` stays quick)."""
    path = resources.files("fpga_robotics.scenario") / "shipped" / f"{DEFAULT_SCENARIO}.toml"
    value = tomllib.loads(path.read_text()).get(section, {}).get(key)
    return "the scenario's" if value is None else f"the scenario's; {DEFAULT_SCENARIO}: {value}"


def build_parser(prog="fpga-robotics run"):
    p = CommandParser(
        prog=prog,
        description="Run a design (the scenario's, FollowTarget by default, or --design REF) "
        "in closed loop with a simulated robot, its sensors and people, and check the "
        "scenario's pass criteria.",
    )
    p.add_argument(
        "--scenario",
        default=DEFAULT_SCENARIO,
        metavar="NAME|PATH",
        help="a shipped scenario (see --list-scenarios) or a .toml file",
    )
    p.add_argument("--list-scenarios", action="store_true", help="list the shipped scenarios")
    p.add_argument(
        "--backend",
        default="auto",
        choices=("auto", *BACKEND_NAMES),
        help="design simulator (default auto: the fastest compiled one available)",
    )
    p.add_argument(
        "--resolution",
        metavar="WxH",
        help=f"camera and design resolution (default: {_scenario_default('camera', 'resolution')})",
    )
    p.add_argument(
        "--color",
        choices=tuple(COLOR_SELECT),
        help=f"initial colour select (default: {_scenario_default('color', 'initial')})",
    )
    p.add_argument(
        "--target-color",
        choices=tuple(TARGET_CLOTHING),
        metavar="C",
        help="dress the target person in C and follow C (colour select, unless --color "
        "gives another); one of " + ", ".join(TARGET_CLOTHING),
    )
    p.add_argument(
        "--duration",
        type=float,
        metavar="S",
        help=f"simulated seconds (default: {_scenario_default('sim', 'duration')})",
    )
    p.add_argument("--seed", type=int, metavar="N", help="random seed (default: the scenario's)")
    p.add_argument("--realtime", action="store_true", help="pace the simulation to the clock")
    p.add_argument("--summary", metavar="PATH", help="write the summary as JSON")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a scenario value, e.g. robot.mass=12 (repeatable; TOML values)",
    )
    p.add_argument(
        "--rerun",
        default="auto",
        metavar="MODE",
        help="viewer: save[:PATH.rrd] (plain save: a new name under runs/), spawn, "
        "connect[:URL], serve[:ADDRESS], off; default auto = spawn with a "
        "display, else save",
    )
    # Recording options default to None, so that one given without a recording is refused.
    p.add_argument(
        "--log-every",
        type=int,
        metavar="N",
        help="log every Nth frame's images to the viewer (default: 1)",
    )
    p.add_argument(
        "--record-camera",
        choices=("rgb444", "rgb888"),
        help="the camera frame in the recording: rgb444 (default) as the design receives it, "
        "each channel's top 4 bits; rgb888 the full 8-bit render (about 5 times the file)",
    )
    p.add_argument(
        "--source",
        metavar="camera:N|VIDEO|FOLDER|IMAGE|bag:PATH[:TOPIC]",
        help="run the design on real frames instead of the simulation (no physics)",
    )
    p.add_argument("--max-frames", type=int, metavar="N", help="with --source: stop after N")
    p.add_argument(
        "--shadow",
        metavar="SPEC",
        help="run a second design on the same frames without letting it drive: a "
        "preset name (published) and/or design KEY=VALUE items separated by ';' "
        "(e.g. 'diff_min=5;kp_num=2'), or in real-clock timing a design "
        "reference (e.g. wall_stop_v1.py:WallStop, or verilog:v1.v with "
        "--shadow-ports); the summary reports where they differ",
    )
    p.add_argument(
        "--shadow-continue",
        action="store_true",
        help="with --shadow: once the shadow would drive differently, let it drive from "
        "there (the world restored at that point) and report its own run beside the "
        "primary's",
    )
    p.add_argument(
        "--shadow-ports",
        metavar="MAP",
        help="the port map of a Verilog shadow design (--shadow verilog:TOP.v[,MORE.v...], "
        "docs/foreign.md)",
    )
    p.add_argument(
        "--shadow-param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="with --shadow FILE.py:Name: a parameter of the shadow design (repeatable); "
        "it has the scenario's [design.params] its signature takes, these on top",
    )
    p.add_argument(
        "--shadow-backend",
        choices=("auto", *BACKEND_NAMES),
        default=None,
        help="simulator of the shadow design (default: the same as --backend)",
    )
    p.add_argument(
        "--design",
        metavar="REF",
        help="the design to run instead of the scenario's design.top: a built-in "
        "name, FILE.py:Name or package.module:Name (an Amaranth component, "
        "docs/your_design.md), or verilog:TOP.v[,MORE.v...] with --ports "
        "(on CXXRTL or Verilator, docs/foreign.md)",
    )
    p.add_argument(
        "--ports", metavar="PORTS.toml", help="with --design: the port map of the Verilog design"
    )
    p.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="a parameter of the design (--set design.params.NAME=VALUE; a Verilog "
        "design's top-module parameter; repeatable)",
    )
    p.add_argument(
        "--define",
        action="append",
        default=[],
        metavar="NAME[=VALUE]",
        help="with a Verilog design: a `define macro read before its files "
        "(--set design.defines.NAME=VALUE; repeatable)",
    )
    p.add_argument(
        "--runtime",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="with a Verilog design: hold its [runtime] input NAME at VALUE for the "
        "run (repeatable; e.g. mutsel=3 selects a mutant, docs/mutation.md)",
    )
    p.add_argument(
        "--save-video",
        metavar="PATH.mp4|PATH.avi",
        help="also write the camera frames as a video (try it with --source)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument(
        "--strict",
        action="store_true",
        help="refuse a scenario that loads with warnings (a waypoint inside "
        "furniture, a check no run can meet...) instead of printing them",
    )
    add_ros_arguments(p)  # --bag, --live, --interactive, --paused, --replay-inputs
    return p


class Progress:
    """A progress bar on stderr: redrawn in place on a terminal, a few plain lines otherwise."""

    def __init__(self, label, stream=None):
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.label = label
        self.start = time.perf_counter()
        self._last_draw = 0.0
        self._last_decile = -1

    def __call__(self, done, total):
        now = time.perf_counter()
        if total is None:  # open-ended source
            if self.tty and (now - self._last_draw > 0.1):
                self.stream.write(f"\r{self.label}: {done} frames")
                self.stream.flush()
                self._last_draw = now
            return
        if self.tty:
            if now - self._last_draw < 0.1 and done < total:
                return
            self._last_draw = now
            width = 30
            filled = int(width * done / total)
            rate = done / max(now - self.start, 1e-9)
            self.stream.write(
                f"\r{self.label} [{'#' * filled}{'.' * (width - filled)}] "
                f"{done}/{total} frames, {rate:.0f} fps"
            )
            self.stream.flush()
        else:
            decile = 10 * done // total
            if decile != self._last_decile and decile % 2 == 0:
                self._last_decile = decile
                self.stream.write(f"{self.label}: {10 * decile}% ({done}/{total} frames)\n")
                self.stream.flush()

    def finish(self):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()


def design_override(reference):
    """``--design REF`` (not ``verilog:``) as the override ``design.top="REF"``, a file path
    made absolute (a scenario file's relative paths are from its own folder)."""
    where, sep, name = reference.rpartition(":")
    if sep and where.endswith(".py"):
        reference = f"{Path(where).expanduser().resolve()}:{name}"
    return f"design.top={json.dumps(reference)}"


def _verilog_overrides(args, items):
    """``--design verilog:FILES`` (and ``--ports``) as the scenario's ``design.top`` (and
    ``design.ports``), paths made absolute: the scenario is loaded with the Verilog design
    in place of its own (its timing, no parameters of the design it replaces)."""
    files = [f for f in args.design[len("verilog:") :].split(",") if f.strip()]
    paths = [Path(f).expanduser() for f in [*files, args.ports or ""]]
    if not files or args.ports is None or not all(p.is_file() for p in paths):
        return []  # the scenario's port map, or _design_files says what --design needs
    if args.backend not in FOREIGN_BACKENDS:
        return []  # _design_files names the backends
    absolute = ",".join(str(Path(f).expanduser().resolve()) for f in files)
    ports = str(Path(args.ports).expanduser().resolve())
    return [f"design.top={json.dumps('verilog:' + absolute)}", f"design.ports={json.dumps(ports)}"]


def take_design_reference(args, scenario):
    """After loading: a ``--design`` reference other than ``verilog:`` is the scenario's
    ``design.top`` now (``_overrides``); ``args.design`` keeps only Verilog files.
    ``args.design_option`` names the design in its errors as the user gave it: ``--design``,
    else the scenario's key."""
    if args.design is not None:
        args.design_option = "--design"
    elif scenario.data["design"].get("verilog") is not None:
        args.design_option = "design.verilog"
    else:
        args.design_option = "design.top"
    if args.design is None or args.design.startswith("verilog:"):
        return
    args.design = None  # the scenario's Verilog files went with its design (load)


def load_run_scenario(args):
    """The scenario a run of ``args`` runs: ``--scenario`` with the command line's overrides.
    The ones that put ``--design verilog:`` in place are not recorded as the run's own
    (its summary names the design by ``--design``, as before)."""
    items = _overrides(args)
    verilog = _verilog_overrides(args, items) if _is_verilog(args) else []
    scenario = load_scenario(args.scenario, [*items, *verilog])
    chosen = scenario.data["sim"]["timing"] == "auto" and scenario.sim.timing == "compressed"
    if chosen and scenario.top not in TOPS and args.shadow is not None:
        # A shadow beside a design of one's own is a design on pins (FollowTarget parameters
        # compare FollowTarget's frames): "auto" is real-clock timing then, for a camera-only
        # design too.
        items.append('sim.timing="real_clock"')
        scenario = load_scenario(args.scenario, [*items, *verilog])
    if not verilog:
        return scenario
    return dataclasses.replace(scenario, overrides=tuple(items))


def _is_verilog(args):
    return args.design is not None and args.design.startswith("verilog:")


def _check_color_option(args, scenario):
    """``--color`` sets a camera design's colour select: a design without a camera input
    (FollowLine, a design of one's own or a Verilog port map without a pixel stream) has
    none to set, nor has a camera design without one (no ``color_sel`` input, a port map
    without ``[color]``): the option would be ignored."""
    if args.color is None:
        return
    top = scenario_top(scenario) if scenario.foreign is not None else TOPS.get(scenario.top)
    top = top or scenario_top(scenario)
    if not top.camera:
        raise UsageError(
            f"--color sets the colour select of a camera design; {top.name} (scenario "
            f"{scenario.name!r}) has no camera input"
        )
    if scenario.foreign is not None:
        select = load_port_map(scenario.foreign.ports).color_port is not None
    else:  # a built-in camera design has one; a design of one's own binds its color_sel
        select = "color_sel" in top.bindings.get("camera", {"color_sel": None})
    if not select:
        raise UsageError(
            f"--color sets the colour select of a camera design; {top.name} (scenario "
            f"{scenario.name!r}) has none (a color_sel input; in a port map, [color])"
        )


#: ``run``'s shorthand options and the ``--set`` key each one sets.
_SHORTHANDS = {
    "duration": "sim.duration",
    "resolution": "camera.resolution",
    "color": "color.initial",
}


def _overrides(args):
    items = list(args.overrides)
    items += [
        f"design.params.{name}={json.dumps(value)}"
        for name, value in design_params_from_items(getattr(args, "param", [])).items()
    ]
    items += [
        f"design.defines.{name}={json.dumps(value)}"
        for name, value in defines_from_items(getattr(args, "define", [])).items()
    ]
    # Both given, one would silently win while the summary recorded the two values.
    for option, key in _SHORTHANDS.items():
        given = [item for item in items if item.split("=", 1)[0].strip() == key]
        if getattr(args, option) is not None and given:
            raise UsageError(f"--{option} and --set {given[0]} both set {key}: give one of them")
    if args.design is not None and not args.design.startswith("verilog:"):
        if args.ports is not None:
            raise UsageError(
                "--ports is the port map of a Verilog design: it goes with --design verilog:FILE.v"
            )
        items.append(design_override(args.design))
    if args.resolution is not None:
        w, h = parse_resolution(args.resolution)
        items.append(f'camera.resolution="{w}x{h}"')
    if args.duration is not None:
        if not args.duration > 0:
            raise UsageError(f"--duration must be > 0 seconds, got {args.duration}")
        items.append(f"sim.duration={float(args.duration)!r}")
    if args.color is not None:
        items.append(f'color.initial="{args.color}"')
    return items


def _video(path, fps):
    """A ``CameraVideo`` context for ``--save-video``, or a context that yields None."""
    if path is None:
        return contextlib.nullcontext()

    return CameraVideo(path, fps)


def shadow_designs(args, scenario):
    """``(shadow_scenario, params_scenario)`` of ``--shadow``: the scenario running a second
    design on pins (``--shadow REF``, real-clock timing), or the scenario with FollowTarget's
    other parameters (a preset, ``KEY=VALUE`` items: compressed timing); None for the one
    not given. Checked before anything is built, an error naming ``--shadow``."""
    spec = args.shadow
    if args.shadow_ports is not None and not str(spec).startswith("verilog:"):
        raise UsageError(
            "--shadow-ports is the port map of a Verilog shadow design: it goes with "
            "--shadow verilog:FILE.v"
        )
    reference = spec is not None and is_design_reference(spec)
    if args.shadow_param and not reference:
        raise UsageError(
            "--shadow-param gives a shadow design its parameters: it goes with "
            "--shadow FILE.py:Name (a design reference)"
        )
    if spec is None:
        return None, None
    if reference:
        shadow = _shadow_scenario(
            scenario,
            spec,
            args.shadow_ports,
            args.shadow_param,
            _file_design_params(args, scenario),
        )
        return shadow, None
    if scenario.top not in TOPS and scenario.foreign is None:
        # Whatever the timing, the shadow would be FollowTarget, not the design changed.
        raise UsageError(
            f"--shadow {spec}: a preset or KEY=VALUE items shadow FollowTarget with other "
            f"parameters; the design here is {scenario.top}: shadow it with a design "
            f"reference, --shadow {scenario.top} --shadow-param NAME=VALUE (or its previous "
            f"version's FILE.py:Name)"
        )
    if scenario.sim.timing == "real_clock":
        raise UsageError(
            f"--shadow {spec}: a preset or KEY=VALUE items shadow FollowTarget with other "
            f"parameters, frame by frame, in compressed timing; scenario {scenario.name!r} "
            f"runs in real-clock timing, where --shadow takes a design reference "
            f"(FILE.py:Name, a built-in design's name, verilog:FILE.v)"
        )
    return None, _shadow_params_scenario(scenario, spec)


def _file_design_params(args, scenario):
    """The scenario's ``[design.params]`` as its file (and ``--set``) give them: those a
    primary ``--design verilog:...`` dropped (it takes none) are still the shadow's."""
    if not _is_verilog(args) or args.scenario is None:
        return scenario.design_params
    return load_scenario(args.scenario, scenario.overrides).design_params


def _shadow_params(scenario, spec):
    """The FollowTarget parameters of ``--shadow SPEC`` (a preset, ``KEY=VALUE`` items)."""
    return _shadow_params_scenario(scenario, spec).params


def _shadow_params_scenario(scenario, spec):
    """The scenario with the FollowTarget parameters ``--shadow`` describes. Only they
    reach the shadow (a backend of whole frames): an item that changes the design itself
    (``top``, ``verilog``, a design's tables or params) is refused, not ignored."""
    try:
        shadow = scenario.with_overrides(shadow_overrides(spec))
    except (ValueError, ScenarioError) as exc:
        raise UsageError(f"--shadow {spec}: {exc}") from None
    design = ("top", "foreign", "design_tables", "design_params")
    if any(getattr(shadow, key) != getattr(scenario, key) for key in design):
        raise UsageError(
            f"--shadow {spec}: in compressed timing the shadow is FollowTarget with other "
            f"[design] values (a preset, KEY=VALUE items), not another design; a second "
            f"design runs beside in real-clock timing: --set sim.timing=real_clock "
            f"--shadow REF (FILE.py:Name, a built-in design's name)"
        )
    return shadow


def _shadow_scenario(scenario, spec, ports, params, design_params):
    """With ``--shadow REF`` (a design reference): the scenario running that design instead,
    with those of ``design_params`` (the scenario's) that its signature takes and ``params``
    (``--shadow-param NAME=VALUE``) on top; a Verilog one, ``verilog:FILES`` with ``ports``,
    takes none."""
    if scenario.sim.timing != "real_clock":
        raise UsageError(
            f"--shadow {spec}: a second design runs on pins, in real-clock "
            f"timing; scenario {scenario.name!r} runs in compressed timing "
            f"(compare FollowTarget parameters there: --shadow KEY=VALUE)"
        )
    if not spec.startswith("verilog:"):
        overrides = [
            design_override(spec),
            *_shadow_param_overrides(design_params, spec, params),
        ]
        try:
            return scenario.with_overrides(overrides)
        except ScenarioError as exc:
            text = str(exc)
            for name in (item.partition("=")[0].strip() for item in params):
                # A value given as --shadow-param is that option's, not [design.params]'.
                if text.startswith(f"design.params.{name} "):
                    raise UsageError(
                        f"--shadow-param {name}{text[len(f'design.params.{name}') :]}"
                    ) from None
            raise UsageError(f"--shadow {spec}: {text}") from None
    if params:
        raise UsageError(
            f"--shadow-param: a Verilog shadow design ({spec}) takes no parameters; "
            f"set them in the Verilog (or tie inputs in its port map's [constants])"
        )
    files = [f for f in spec[len("verilog:") :].split(",") if f.strip()]
    if not files:
        raise UsageError(f"--shadow must be verilog:FILE.v[,MORE.v...], got {spec!r}")
    if ports is None:
        raise UsageError(
            "--shadow verilog:... needs --shadow-ports PORTS.toml (the shadow design's port map)"
        )
    for what, path in [*(("--shadow", f) for f in files), ("--shadow-ports", ports)]:
        if not Path(path).expanduser().is_file():
            raise UsageError(f"{what}: no such file: {path}")
    absolute = ",".join(str(Path(f).expanduser().resolve()) for f in files)
    try:
        return scenario.with_overrides(
            [
                f"design.top={json.dumps('verilog:' + absolute)}",
                f"design.ports={json.dumps(str(Path(ports).expanduser().resolve()))}",
                "design.params={}",  # the primary's are not a Verilog design's
            ]
        )
    except ScenarioError as exc:
        raise UsageError(f"--shadow-ports {ports}: {exc}") from None


def _shadow_param_overrides(design_params, spec, params):
    """The overrides that give the shadow design ``spec`` its ``[design.params]``: those of
    ``design_params`` (the scenario's) its signature takes (a previous version may lack a newer parameter), then
    ``params`` (``NAME=VALUE`` items, values as ``--set`` takes them)."""
    try:
        takes = design_parameters(spec)
    except UsageError as exc:  # the reference's DesignError: no such file, no such name ...
        raise UsageError(f"--shadow {spec}: {exc}") from None
    given = {}
    for item in params:
        name, sep, value = (part.strip() for part in item.partition("="))
        if not sep or not name.isidentifier():
            raise UsageError(f"--shadow-param needs NAME=VALUE (e.g. stop_mm=100), got {item!r}")
        if spec in TOPS:
            raise UsageError(
                f"--shadow-param: the built-in design {spec!r} takes its parameters from "
                f"the scenario's [design], not --shadow-param"
            )
        if takes is not None and name not in takes:
            raise UsageError(
                f"--shadow-param {name}: {spec} takes no parameter {name!r}; "
                f"it takes: {', '.join(takes) or 'none'}"
            )
        given[name] = value
    kept = {n: v for n, v in design_params.items() if takes is None or n in takes}
    missing = [n for n, required in (takes or {}).items() if required and n not in kept]
    missing = [n for n in missing if n not in given]
    if missing:
        raise UsageError(
            f"--shadow {spec}: parameter {missing[0]!r} has no default and the scenario "
            f"does not give it; give it with --shadow-param {missing[0]}=VALUE"
        )
    # One table, each parameter once with the shadow's value (its summary lists its own).
    values = {n: json.dumps(v) for n, v in kept.items()}
    values.update((n, _toml_text(v)) for n, v in given.items())
    return ["design.params={" + ", ".join(f"{n} = {v}" for n, v in values.items()) + "}"]


def _toml_text(text):
    """A ``--set`` value as TOML text: a bare word is a string, as ``--set`` reads it."""
    try:
        tomllib.loads(f"v = {text}")
    except tomllib.TOMLDecodeError:
        return json.dumps(text.strip())
    return text.strip()


def _shadow_args(args, shadow_scenario):
    """The options a shadow design on pins is opened with: ``--shadow-backend`` (default
    ``--backend``; ``auto`` for a Verilog shadow beside a design on pysim), and of the
    ``--runtime`` values those its own port map declares."""
    shadow_args = copy.copy(args)
    shadow_args.backend = args.shadow_backend or args.backend
    shadow_args.runtime = []
    if shadow_scenario.foreign is None:
        return shadow_args
    if args.shadow_backend is None and args.backend not in FOREIGN_BACKENDS:
        shadow_args.backend = "auto"
    if shadow_args.backend not in FOREIGN_BACKENDS:
        raise UsageError(
            f"a Verilog shadow design runs on the cxxrtl or verilator backend, not "
            f"--shadow-backend {shadow_args.backend!r}"
        )
    declared = load_port_map(shadow_scenario.foreign.ports).runtime
    shadow_args.runtime = [
        item for item in (args.runtime or []) if item.split("=", 1)[0].strip() in declared
    ]
    return shadow_args


def _check_continue(args, ros):
    """--shadow-continue's companions, checked before anything is built."""
    if not args.shadow_continue:
        return
    if args.shadow is None:
        raise UsageError("--shadow-continue lets the --shadow design drive: give --shadow SPEC")
    if ros.live_control or ros.replay is not None or args.realtime:
        raise UsageError(
            "--shadow-continue replays the run without live inputs or pacing: leave out "
            "--realtime, --live, --interactive and --replay-inputs"
        )


def _run_continued(args, scenario, design, shadow, shadow_scenario, **run_args):
    """The run with its shadow, then the shadow's own run from where it parts
    (fpga_robotics.loop.continuation); the shadow's path drawn on the viewer's map."""

    continued = run_continued(
        scenario,
        design=design,
        shadow=shadow,
        shadow_scenario=shadow_scenario,
        seed=args.seed,
        shadow_label=args.shadow,
        **run_args,
    )
    recorder = run_args.get("recorder")
    if recorder is not None:
        t = continued.shadow.trajectory
        recorder.log_trail("shadow", t["x"], t["y"])
    return continued


def _format_continued(s, label):
    """Lines for the human summary: the shadow design's own run."""

    parted = s["parted_at_frame"]
    where = "never drove differently" if parted is None else f"drives from frame {parted}"
    lines = [f"  shadow {label} on its own ({where}):"]
    return lines + ["  " + line for line in format_summary(s).splitlines()]


def _dress_target(scenario, color, select=True):
    """The scenario with its target person dressed in ``color`` and, with ``select``, the
    design's colour select set to it (later colour changes of the scenario are kept)."""
    scenario, index = scenario.target_person()
    if index is None:
        raise UsageError(f"--target-color: scenario {scenario.name!r} has no target person")
    rgb = "[" + ", ".join(str(c) for c in TARGET_CLOTHING[color]) + "]"
    dress = [f"people.{index}.shirt_color={rgb}", f"people.{index}.trousers_color={rgb}"]
    return scenario.with_overrides(dress + ([f'color.initial="{color}"'] if select else []))


def _open_backend(name, params, quiet=False):
    def tell(text):  # a first run compiles the model for seconds: say so
        if not quiet:
            print(f"{text} ...", file=sys.stderr, flush=True)

    try:
        return make_backend(name, params, on_build=tell)
    except (BackendError, ValueError, ImportError) as exc:
        raise UsageError(f"backend {name!r} cannot run here: {exc}") from None


def _open_pin_design(args, scenario, option=None, backend_option="--backend"):
    """The scenario's design on a pin-level backend (real-clock timing); ``option`` names
    the design in an error of its Verilog (``--shadow REF`` for a shadow design; default
    ``args.design_option``), ``backend_option`` the option that picks its backend."""
    option = option or args.design_option

    def tell(text):
        if not args.quiet:
            print(f"{text} ...", file=sys.stderr, flush=True)

    if scenario.foreign is not None:  # a Verilog design on pins: on CXXRTL or Verilator
        try:
            design = make_pin_backend(args.backend, scenario, on_build=tell)
        except (BackendError, PinError) as exc:
            text = str(exc).replace("--backend verilator", f"{backend_option} verilator")
            raise UsageError(f"{option}: {text}".splitlines()[0]) from None
        try:
            apply_runtime(design, args)  # held from every reset on
        except UsageError:
            design.close()
            raise
        return design
    try:
        return make_pin_backend(args.backend, scenario, on_build=tell)
    except UsageError:  # the design's own (no clock ...): already what to fix
        raise
    except (BackendError, PinError, ValueError, ImportError) as exc:
        raise UsageError(f"backend {args.backend!r} cannot run here: {exc}") from None


def _with_design_files(args, scenario):
    """The scenario with ``--design``/``--ports`` as its foreign design (real-clock timing
    runs the design the scenario names)."""
    design_files = _design_files(args, scenario.foreign)
    if design_files is None:
        return scenario

    files, ports = design_files
    overrides = scenario.foreign.overrides if scenario.foreign is not None else None
    return dataclasses.replace(
        scenario, foreign=ForeignDesignFiles(tuple(files), str(ports), overrides)
    )


class PortMapUnpaired(UsageError):
    """A Verilog design without a port map, or a port map without a Verilog design (a
    campaign says it in its file's words when the file gave them)."""


def _design_files(args, foreign=None):
    """The Verilog files and port map of the foreign design (None without one): ``--design``
    and ``--ports``, each overriding the scenario's ``[design] verilog`` / ``ports``
    (``foreign``, a ``ForeignDesignFiles``); checks they go together."""
    if args.design is None and foreign is None:
        if args.ports is not None:
            raise PortMapUnpaired("--ports goes with --design verilog:FILE.v")
        if getattr(args, "runtime", None):
            raise UsageError(
                "--runtime sets [runtime] inputs of a Verilog design: it goes with "
                "--design verilog:FILE.v (or a scenario's design.verilog)"
            )
        return None
    runtime_values(args)  # a malformed item is an error before any build
    if args.design is not None:
        if not args.design.startswith("verilog:") or not args.design[len("verilog:") :].strip(","):
            raise UsageError(f"--design must be verilog:FILE.v[,MORE.v...], got {args.design!r}")
        files = [f for f in args.design[len("verilog:") :].split(",") if f]
    else:
        files = list(foreign.verilog)
    ports = (
        args.ports if args.ports is not None else (foreign.ports if foreign is not None else None)
    )
    if ports is None:
        raise PortMapUnpaired("--design needs --ports PORTS.toml (the design's port map)")
    if args.backend not in FOREIGN_BACKENDS:
        what = "--design" if args.design is not None else "the scenario's design.verilog"
        raise UsageError(f"{what} runs on the cxxrtl or verilator backend, not {args.backend!r}")
    return files, ports


def _open_design(args, scenario):
    """The main design in compressed timing: ``--design`` (or the scenario's foreign
    design), a design of one's own frame by frame on its pin backend, else FollowTarget, on
    ``--backend``."""
    params = scenario.params
    design_files = _design_files(args, scenario.foreign)
    if design_files is None and scenario.top not in TOPS:
        return _open_pin_frames(args, scenario)
    if design_files is None:
        return _open_backend(args.backend, params, args.quiet)
    files, ports = design_files

    def tell(text):
        if not args.quiet:
            print(f"{text} ...", file=sys.stderr, flush=True)

    try:
        # Outputs the map does not name stay None: absent in the summary and the viewer.
        backend = open_foreign_frames(
            args.backend,
            params,
            files=files,
            port_map=ports,
            on_build=tell,
            overrides=scenario.foreign.overrides if scenario.foreign is not None else None,
        )
    except BackendError as exc:
        raise UsageError(f"{args.design_option}: {exc}".splitlines()[0]) from None
    missing = [k for k in ("motor_left", "motor_right") if k not in backend.design.port_map.outputs]
    if missing:
        backend.close()
        raise UsageError(
            f"{args.design_option}: the closed loop needs outputs.{missing[0]} in the port map"
        )
    design = _UserDesign(backend, args.design_option)
    try:
        apply_runtime(design, args)
    except UsageError:
        backend.close()
        raise
    return design


def _open_pin_frames(args, scenario):
    """A camera-only design of one's own in compressed timing (fpga_robotics.loop.pin_frames)
    on the pin backend ``--backend``."""
    check_frame_backend(args.backend, scenario)
    return PinFrames(scenario, _open_pin_design(args, scenario))


def runtime_values(args):
    """``--runtime NAME=VALUE`` items as ``{name: int}`` (``UsageError`` for a bad item)."""
    values = {}
    for item in getattr(args, "runtime", None) or ():
        name, sep, value = item.partition("=")
        try:
            if not sep or not name.strip():
                raise ValueError
            values[name.strip()] = int(value.strip(), 0)
        except ValueError:
            raise UsageError(
                f"--runtime needs NAME=VALUE with an integer VALUE, got {item!r}"
            ) from None
    return values


def apply_runtime(design, args):
    """Hold the design's ``[runtime]`` inputs at the ``--runtime`` values (a design opened
    once and reused for several runs gets its values again before each)."""
    for name, value in runtime_values(args).items():
        try:
            design.set_runtime(name, value)
        except (BackendError, PinError) as exc:
            raise UsageError(f"--runtime: {exc}") from None


class _UserDesign:
    """A foreign design whose per-frame errors (a named timeout, a broken stream) are the
    user's to fix: reported as one line and exit 2, like a bad port map, after ``option``
    (how the design was given: ``--design``, ``design.verilog``)."""

    def __init__(self, backend, option):
        self._backend = backend
        self._option = option

    def process_frame(self, frame, color_sel="red"):
        try:
            return self._backend.process_frame(frame, color_sel)
        except BackendError as exc:
            raise UsageError(f"{self._option}: {exc}") from None

    def __getattr__(self, name):
        return getattr(self._backend, name)


def _recording_name(args, scenario):
    """The stem of the default recording: the scenario's name, or the source's."""
    if args.source is not None:
        return Path(str(args.source).replace(":", "_")).stem
    return scenario.name


def _check_recording(args, name):
    """The ``--rerun`` mode and the file it would write, checked before any build: a run
    never fails on its recording after the work. Returns that file (None without one)."""
    if args.rerun == "off":
        return None
    from fpga_robotics.viz.modes import parse_mode  # lazy: viz imports rerun (~1 s)

    mode = parse_mode(args.rerun, default_path=f"runs/{name}.rrd")
    if mode.path is not None:
        check_output_path(mode.path, what="recording")
    return mode.path


def _input_paths(args):
    """The files and folders the run reads, as ``(option, path)``: no output may be one, be
    inside one or hold one (a ``--source`` is often a real robot's recording, made once)."""
    paths = [
        ("--scenario", args.scenario),
        ("--replay-inputs", args.replay_inputs),
        ("--ports", args.ports),
        ("--shadow-ports", args.shadow_ports),
    ]
    for option, reference in (("--design", args.design), ("--shadow", args.shadow)):
        if reference is not None and reference.startswith("verilog:"):
            paths += [(option, f) for f in reference[len("verilog:") :].split(",")]
        elif reference is not None:
            paths.append((option, reference.rpartition(":")[0]))  # FILE.py:Name
    paths = [(option, Path(p).expanduser()) for option, p in paths if p]
    paths = [(option, p) for option, p in paths if p.is_file()]  # not names: files read
    if args.source is not None and args.source.startswith("bag:"):
        from fpga_robotics.ros.bag_source import parse_bag_spec  # lazy: rosbags, for bags only

        bag, _topic = parse_bag_spec(args.source)
        # A ROS 2 bag is its folder, whichever of its files was named.
        paths.append(("--source", bag.parent if bag.suffix in (".mcap", ".db3") else bag))
    elif args.source is not None and not args.source.startswith("camera:"):
        paths.append(("--source", Path(args.source)))  # a video file or a folder of images
    return paths


def _design_inputs(args, scenario):
    """The loaded scenario's design files, as ``(option, path)``: a design of one's own's
    source (the modules it imports beside it, its package) and a scenario's Verilog."""
    files = design_source_files(scenario.top)
    option = args.design_option
    paths = [(option if i == 0 else f"{option}'s module", Path(f)) for i, f in enumerate(files)]
    if scenario.foreign is not None:
        paths += [("design.verilog", Path(f)) for f in scenario.foreign.verilog]
        paths.append(("design.ports", Path(scenario.foreign.ports)))
    return paths


def _output_paths(args, recording):
    """The files and folders the run writes, as ``(option, path)``; ``recording`` is the
    ``--rerun`` mode's file."""
    paths = [
        ("--bag", args.bag),
        ("the recording", recording),
        ("--save-video", args.save_video),
        ("--summary", args.summary),
    ]
    return [(option, path) for option, path in paths if path is not None]


def _check_renderer(scenario):
    """A 3D scenario needs the ``realistic`` extra (MuJoCo): said before the design is built,
    not when the first frame is drawn."""
    if scenario.camera.renderer != "mujoco":
        return

    try:
        load_mujoco()
    except Render3DUnavailable as exc:
        raise UsageError(f'camera.renderer = "mujoco": {exc}') from None


def _refuse_idle_options(args):
    """Options that would do nothing, refused: those of the recording with ``--rerun off``,
    ``--shadow-backend`` without a shadow."""
    if args.log_every is not None and args.log_every < 1:
        raise UsageError(f"--log-every must be >= 1, got {args.log_every}")
    for option, value in (("--log-every", args.log_every), ("--record-camera", args.record_camera)):
        if value is not None and args.rerun == "off":
            raise UsageError(f"{option} shapes the recording: it does not go with --rerun off")
    if args.shadow_backend is not None and args.shadow is None:
        raise UsageError("--shadow-backend is the simulator of the --shadow design: give --shadow")


def _open_recorder(args, name):
    if args.rerun == "off":
        return None
    from fpga_robotics.viz import open_recorder  # lazy: viz imports rerun (~1 s)

    # An option not given keeps open_recorder's default (every frame, rgb444).
    options = {"log_every": args.log_every, "camera": args.record_camera}
    recorder = open_recorder(
        args.rerun,
        default_path=f"runs/{name}.rrd",
        app_id="fpga_robotics",
        **{key: value for key, value in options.items() if value is not None},
    )
    for line in recorder.pop_notices():  # where a live viewer is, or why it fell back
        print(line, file=sys.stderr)
    return recorder


def _close_recorder(recorder, completed):
    """Close the recording; after an interrupt, say at once where the data is (the summary
    that would say it is not printed)."""
    if recorder is None:
        return []
    text = recorder.close()  # the notices not yet taken, one a line
    notices = text.splitlines() if text else []
    if not completed:
        for line in notices:
            print(line, file=sys.stderr)
        return []
    return notices


def _close_outputs(recorder, ros, completed):
    """Close the ROS outputs (the terminal's modes restored first) and the recording;
    returns their notices, the recording's first."""
    try:
        ros_notices = ros.close(completed)
    finally:
        notices = _close_recorder(recorder, completed)
    return notices + ros_notices


def _frame_callback(video, ros):
    """The ``on_frame`` of a run: the video and the ROS outputs, each when asked for."""
    calls = ([lambda record: video.write(record.camera_rgb)] if video is not None else []) + (
        [ros.on_frame] if ros.active else []
    )
    if not calls:
        return None
    if len(calls) == 1:
        return calls[0]
    return lambda record: [call(record) for call in calls]


def _list_scenarios():
    shipped = shipped_scenarios()
    width = max(len(n) for n in shipped)
    for name, (_path, desc) in shipped.items():
        print(f"{name:<{width}}  {desc}")
    return 0


def _run_source(args, scenario, ros):
    ros.check_closed_loop_only(args.source)
    if scenario.sim.timing == "real_clock":
        raise UsageError(
            f"--source feeds camera frames to the design; scenario "
            f"{scenario.name!r} runs in real-clock timing (design.top = "
            f"{scenario.top!r}, sensors on pins): run it without --source"
        )
    params = scenario.params
    source = open_source(
        args.source, params.width, params.height, args.max_frames, fps=scenario.camera.fps
    )
    try:
        design = _open_design(args, scenario)
        recorder = None
        completed = False
        try:
            recorder = _open_recorder(args, _recording_name(args, scenario))
            for line in ros.open(scenario, closed_loop=False):
                print(line, file=sys.stderr)
            progress = None if args.quiet else Progress("frames")
            out = run_source(
                source,
                design,
                color=scenario.color_initial,
                recorder=recorder,
                progress=progress,
                max_frames=args.max_frames,
                hfov=scenario.camera.hfov,
                robot=parse_world_config(scenario.world).robot.spec,
                on_frame=ros.on_frame if ros.active else None,
            )
            if progress is not None:
                progress.finish()
            completed = True
        finally:
            design.close()
            notices = _close_outputs(recorder, ros, completed)
    finally:
        source.close()
    print(
        f"source {out['source']} ({out['source_kind']})  backend {out['backend']}  "
        f"{out['resolution']}  colour {out['color']}"
    )
    if out["frames"]:
        print(
            f"  {out['frames']} frames, {out['ms_per_frame']:.2f} ms/frame "
            f"(design {out['design_ms_per_frame']:.2f} ms)"
        )
        proximity = out["mean_proximity"]  # None: the design has no proximity output
        print(
            f"  target found in {out['found_frames']} frames ({out['found_fraction']:.0%})"
            + ("" if proximity is None else f", mean proximity {proximity:.2f}")
        )
    else:
        print("  no frames")
    for line in format_extra_outputs(out):
        print(line)
    for line in notices:
        print(line)
    if args.summary:
        write_json_atomic(args.summary, out, what="--summary")
    return 0


def main(argv=None, prog="fpga-robotics run"):
    parser = build_parser(prog)
    args = parser.parse_args(argv)
    if args.list_scenarios:
        # Nothing runs: an option beside it would be ignored, a bad value unnoticed.
        others = parser.given_options(args, ignore={"list_scenarios"})
        if others:
            raise UsageError(f"--list-scenarios takes no other option; got {', '.join(others)}")
        return _list_scenarios()

    inputs = _input_paths(args)  # before --design's file is taken into the scenario
    if args.seed is not None and not 0 <= args.seed <= MAX_SEED:
        raise UsageError(f"--seed must be in 0..{MAX_SEED}, got {args.seed}")
    _refuse_idle_options(args)  # checked now, before a model is built
    if args.summary is not None:  # checked now, not after a long run
        check_output_path(args.summary, what="--summary")
    ros = RosOutputs(args)  # --bag, --live ...: checked now, not after a long run
    scenario = load_run_scenario(args)
    take_design_reference(args, scenario)
    inputs += _design_inputs(args, scenario)
    _check_color_option(args, scenario)
    if args.target_color is not None:
        # An explicit --color is the design's select: the target wears another colour.
        scenario = _dress_target(scenario, args.target_color, select=args.color is None)
    report_warnings(scenario, args.strict, sys.stderr, UsageError)
    recording = _check_recording(args, _recording_name(args, scenario))
    # One output written over another, or over an input, would lose it: refused now.
    check_paths_apart(_output_paths(args, recording), inputs)
    if args.source is not None:
        if args.shadow is not None:
            raise UsageError("--shadow runs in the closed loop only (not with --source)")
        if args.save_video is not None:
            raise UsageError(
                "--save-video writes the simulated camera's frames: it goes with "
                "the closed loop, not with --source"
            )
        if args.max_frames is not None and args.max_frames < 1:
            raise UsageError(f"--max-frames must be >= 1, got {args.max_frames}")
        # Both act on the simulated world only: taken and dropped, they would mislead.
        if args.seed is not None:
            raise UsageError("--seed fixes the simulated world's random choices; --source has none")
        if args.realtime:
            raise UsageError(
                "--realtime paces the simulated world to the clock; with --source the "
                "frames go as fast as the design takes them (a camera's as it delivers them)"
            )
        if args.duration is not None:
            raise UsageError(
                "--duration is the closed loop's length; with --source the frames decide "
                "it (--max-frames N takes the first N)"
            )
        return _run_source(args, scenario, ros)
    if args.max_frames is not None:
        raise UsageError("--max-frames only applies with --source (use --duration)")
    replay_warning = ros.replay_warning(scenario, args.seed)
    if replay_warning is not None:
        print(replay_warning, file=sys.stderr)
    shadow_scenario, params_scenario = shadow_designs(args, scenario)
    shadow_args = None if shadow_scenario is None else _shadow_args(args, shadow_scenario)
    if shadow_scenario is not None and args.shadow_backend == "model":
        raise UsageError(
            "--shadow-backend model runs whole frames; a shadow design on pins needs "
            "--shadow-backend auto, cxxrtl, verilator or pysim"
        )
    shadow_params = None if params_scenario is None else params_scenario.params
    _check_continue(args, ros)
    if args.save_video is not None:
        try:
            check_video_path(args.save_video)
        except VideoPathError as exc:
            raise UsageError(str(exc)) from None

    _design_files(args, scenario.foreign)
    _check_renderer(scenario)
    t0 = time.perf_counter()
    if scenario.sim.timing == "real_clock":
        scenario = _with_design_files(args, scenario)
        check_bindings(scenario)  # before the model is built
        if shadow_scenario is not None:
            try:
                check_bindings(shadow_scenario)
            except UsageError as exc:
                raise UsageError(f"--shadow {args.shadow}: {exc}") from None
        design = _open_pin_design(args, scenario)
    else:
        check_bindings(scenario)  # before the model is built
        design = _open_design(args, scenario)
    shadow = recorder = None
    completed = False
    try:
        if shadow_scenario is not None:
            shadow = _open_pin_design(
                shadow_args, shadow_scenario, f"--shadow {args.shadow}", "--shadow-backend"
            )
        if shadow_params is not None:
            shadow = _open_backend(args.shadow_backend or args.backend, shadow_params, args.quiet)
        setup = time.perf_counter() - t0
        recorder = _open_recorder(args, scenario.name)
        for line in ros.open(scenario):
            print(line, file=sys.stderr)
        progress = None if args.quiet else Progress(scenario.name)
        with _video(args.save_video, scenario.camera.fps) as video:
            if args.shadow_continue:
                continued = _run_continued(
                    args,
                    scenario,
                    design,
                    shadow,
                    shadow_scenario or params_scenario,
                    recorder=recorder,
                    progress=progress,
                    on_frame=_frame_callback(video, ros),
                )
                result = continued.main
            else:
                result = run_scenario(
                    scenario,
                    seed=args.seed,
                    backend=design,
                    recorder=recorder,
                    progress=progress,
                    realtime=args.realtime,
                    shadow=shadow,
                    shadow_label=args.shadow or "shadow",
                    on_frame=_frame_callback(video, ros),
                    controls=ros.controls,
                )
        if progress is not None:
            progress.finish()
        completed = True
    except ShadowDesignError as exc:  # the shadow's own doing, named as --shadow gave it
        raise UsageError(f"--shadow: {exc}") from None
    except DesignError as exc:  # real-clock timing: as _UserDesign reports it on frames
        raise UsageError(f"{args.design_option}: {exc}") from None
    finally:
        design.close()
        if shadow is not None:
            shadow.close()
        notices = _close_outputs(recorder, ros, completed)
    summary = dict(result.summary)
    summary["backend_setup_s"] = round(setup, 3)
    if args.shadow_continue:
        summary["shadow_continued"] = continuation_summary(continued)
    summary.update(ros.summary_items())  # the live inputs, for --replay-inputs
    print(format_summary(summary))

    for line in format_extra_outputs(summary):
        print(line)
    if "shadow" in summary:
        print("\n".join(format_shadow(summary["shadow"])))
    if "shadow_continued" in summary:
        print("\n".join(_format_continued(summary["shadow_continued"], args.shadow)))
    for line in notices:
        print(line)
    if args.save_video is not None:
        print(f"camera frames written to {args.save_video} (try: --source {args.save_video})")
    if args.summary:
        write_json_atomic(args.summary, summary, what="--summary")
    return 0 if summary["verdict"] == "pass" else 1


if __name__ == "__main__":  # python -m fpga_robotics.cli.run: as fpga-robotics run
    run_cli(main, sys.argv[1:], prog="fpga-robotics run")
