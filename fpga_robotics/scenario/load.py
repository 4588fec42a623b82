"""Scenarios as data: load a TOML file, fill defaults, apply ``--set`` overrides, validate.

A scenario file has two kinds of sections. The world's sections (``room``, ``robot``,
``people``, ``lighting``) are passed unchanged to ``World.from_config``, which validates them
(see docs/scenarios.md). The application's sections are validated here:

- ``[sim]``: ``duration`` (s), ``physics_dt`` (s), ``actuation_delay`` (s, default one frame
  period);
- ``[camera]``: ``resolution`` ("WxH"), ``fps``, ``hfov`` (rad), ``mount_height`` (m),
  ``mount_forward`` (m ahead of the robot's centre), ``tilt`` (rad, up positive), ``noise_std``;
  ``sensor`` (``"plain"``: the rendered frame plus ``noise_std``; ``"ov7670"``: the sensor model
  ``fpga_robotics.sim.camera.sensor`` with its ``[camera.ov7670]`` table, docs/camera.md);
- ``[color]``: ``initial`` colour and ``changes = [{at = seconds, color = "..."}, ...]``;
- ``[design]``: any ``FollowTargetParams`` field except ``width``/``height`` (those come from
  the camera resolution), and ``preset`` (``"published"``: ``FollowTargetParams.published()``
  at the camera's resolution, applied first, the other ``design`` keys on top); an error on a
  design that reads none of them (no FollowTarget inside, no camera);
- ``[checks]``: the pass criteria of the scenario (see ``fpga_robotics.checks.summary.CHECKS``).

Top-level keys: ``name``, ``description``, ``seed`` (default seed of a run).

Everything is checked when the scenario is loaded, before a run starts: types and the range
of every key (the key models of ``fpga_robotics.scenario.schema`` and ``sim.world.keys``,
docs/scenarios.md), the relations between keys, the size of the run (physics steps and
camera frames, counted as ``fpga_robotics.loop`` counts them) and the camera's geometry as
the renderer will draw it.
"""

import copy
import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path

from pydantic_core import PydanticCustomError

from fpga_robotics.checks.summary import CHECKS
from fpga_robotics.designs.builtin import TOPS, design_tables, table_class, table_fields
from fpga_robotics.designs.reference import DesignError, resolve_design
from fpga_robotics.hw.errors import ParamError
from fpga_robotics.hw.params import (
    PRESETS,
    FollowTargetParams,
    preset_values,
)
from fpga_robotics.loop.compressed import frame_count
from fpga_robotics.loop.connectors import CONNECTORS, ConnectorError
from fpga_robotics.scenario.connectors import parse_connectors
from fpga_robotics.scenario.errors import ScenarioError
from fpga_robotics.scenario.sanity import scenario_warnings
from fpga_robotics.scenario.schema import (
    MAX_SEED,
    TIMINGS,
    CameraKeys,
    ColorKeys,
    SimKeys,
    TopKeys,
    checks_keys,
    defaults_of,
    design_keys,
    ov7670_keys,
)
from fpga_robotics.sim.backends.port_map import PortMapError, load_port_map
from fpga_robotics.sim.backends.verilog_params import VerilogOverrides
from fpga_robotics.sim.camera.raster import max_hfov, max_tilt, vertical_fov
from fpga_robotics.sim.camera.render3d.options import Lamp, Render3DOptions
from fpga_robotics.sim.camera.sensor import OV7670Params
from fpga_robotics.sim.files import NotTextError, read_user_text
from fpga_robotics.sim.world import World, WorldConfigError
from fpga_robotics.sim.world.config import WORLD_SECTIONS, default_people
from fpga_robotics.sim.world.keys import WORLD_KEY_MODELS
from fpga_robotics.sim.world.lighting import SCHEDULE_SLACK
from fpga_robotics.sim.world.schema import Number, check_of, validate

__all__ = [
    "DEFAULTS",
    "MAX_FILE_BYTES",
    "MAX_FRAMES",
    "MAX_NAME_LENGTH",
    "MAX_PHYSICS_STEPS",
    "MAX_SEED",
    "TIMINGS",
    "WORLD_SECTIONS",
    "CameraConfig",
    "ForeignDesignFiles",
    "Scenario",
    "ScenarioError",
    "SimConfig",
    "load_scenario",
    "override_items",
    "parse_resolution",
    "shipped_scenarios",
]

_TOP_KEYS = tuple(TopKeys.key_names())  # name, description, seed
_APP_SECTIONS = ("sim", "camera", "color", "design", "checks")
#: A foreign Verilog design instead of FollowTarget (docs/foreign.md): its files and port map.
_FOREIGN_KEYS = ("verilog", "ports", "defines")
#: ``design.top`` (fpga_robotics.designs), a buggy ``variant``, and the tops' parameter tables.
_TOP_TABLES = tuple(dict.fromkeys(key for top in TOPS.values() for key in top.tables))
#: ``design.params``: the keyword arguments of a design of one's own (designs/reference.py).
_TOP_DESIGN_KEYS = ("top", "variant", "params", *_TOP_TABLES)


def _section_models():
    """The key model of each application section (``[checks]`` follows its registry)."""
    return {
        "sim": SimKeys,
        "camera": CameraKeys,
        "color": ColorKeys,
        "design": design_keys(),
        "checks": checks_keys(),
    }


#: Defaults of the application's sections (a key absent here is unknown; None: no default),
#: from their key models (fpga_robotics.scenario.schema).
DEFAULTS = {
    "sim": defaults_of(SimKeys),
    "camera": {**defaults_of(CameraKeys), "ov7670": defaults_of(ov7670_keys())},
    "color": defaults_of(ColorKeys),
}
#: Camera and design resolution: the design's limits (``FollowTargetParams``).
WIDTH_RANGE = (16, 4096)
HEIGHT_RANGE = (2, 4096)
#: A run is at most this many physics steps (``sim.duration / sim.physics_dt``) ...
MAX_PHYSICS_STEPS = 10**8
#: ... and this many camera frames (``sim.duration * camera.fps``; about 150 bytes each of
#: trajectory in memory).
MAX_FRAMES = 10**7
#: A scenario's name is a file name (``runs/<name>.rrd``): ASCII letters, digits, ``_ - .``,
#: not starting with ``.`` or ``-``, at most this long.
MAX_NAME_LENGTH = 64
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")
#: A scenario file is at most this large (a few kB is usual).
MAX_FILE_BYTES = 1 << 20


def parse_resolution(text, where="resolution"):
    """``"160x120"`` (or ``[160, 120]``) → ``(160, 120)``; ``ScenarioError`` naming ``where``
    (the key or option that gave it) when malformed."""
    if isinstance(text, (list, tuple)) and len(text) == 2:
        w, h = text
    elif isinstance(text, str) and text.lower().count("x") == 1:
        w, h = text.lower().split("x")
        try:
            w, h = int(w), int(h)
        except ValueError:
            w = h = None
    else:
        w = h = None
    if isinstance(w, bool) or isinstance(h, bool):
        w = h = None
    if not (isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0):
        raise ScenarioError(
            f"{where} must look like WIDTHxHEIGHT, e.g. 160x120, 320x240 or 640x480; got {text!r}"
        )
    return w, h


@dataclass(frozen=True)
class CameraConfig:
    width: int
    height: int
    fps: float
    hfov: float
    mount_height: float | None  # None: the robot model's own mount
    mount_forward: float | None
    tilt: float | None
    noise_std: float
    yaw_offset: float = 0.0  # rad: the mount's yaw off the robot's heading (left positive)
    exposure_drift: float = 0.0  # std of the log brightness gain (CameraConnector)
    sensor: str = "plain"  # "plain" or "ov7670" (sim.sensor, with the parameters below)
    ov7670: OV7670Params = field(default_factory=OV7670Params)
    renderer: str = "raster"  # "raster" or "mujoco" (docs/render3d.md)
    render3d: object = None  # sim.render3d.Render3DOptions

    @property
    def frame_period(self):
        return 1.0 / self.fps


#: In real-clock timing the readout and the processing are simulated, so the default
#: actuation delay is only the command's trip to the motor controller (one SPI message), s.
REAL_CLOCK_ACTUATION_DELAY = 0.001

#: The design's clock when ``sim.clock_hz`` is unset, Hz.
DEFAULT_CLOCK_HZ = 50e6


@dataclass(frozen=True)
class SimConfig:
    duration: float
    physics_dt: float
    actuation_delay: float
    timing: str = "compressed"  # "compressed" or "real_clock" (never "auto" once loaded)
    clock_hz: float = DEFAULT_CLOCK_HZ


@dataclass(frozen=True)
class ForeignDesignFiles:
    """A scenario's foreign Verilog design: its files and port map, as paths that exist
    (relative ones resolved against the scenario file's folder)."""

    verilog: tuple
    ports: str
    #: ``[design.params]`` and ``[design.defines]`` (``sim.backends.verilog_params``).
    overrides: object = None


@dataclass(frozen=True, eq=False)
class Scenario:
    """A validated scenario.

    Attributes
    ----------
    name : str
        Its name (file stem unless the file says otherwise).
    source : str
        Where it was loaded from (a path).
    data : dict
        The whole scenario with defaults filled and overrides applied (plain TOML types).
    world : dict
        The world's sections, for ``World.from_config``.
    camera, sim : CameraConfig, SimConfig
    color_initial : str
    color_changes : tuple of (time_s, colour)
    params : FollowTargetParams
        The design's parameters (resolution from ``camera``, the rest from ``[design]``).
    checks : dict
        Pass criteria, name → limit.
    overrides : tuple of str
        The ``--set`` overrides applied, as given.
    foreign : ForeignDesignFiles or None
        ``[design] verilog = [...]`` and ``ports = "..."``: a foreign Verilog design to run
        instead of FollowTarget (docs/foreign.md), paths resolved; None without them.
    top : str
        ``design.top``: the design to run, a built-in name or a design reference
        (``fpga_robotics.designs.reference``; a file path made absolute).
    design_params : dict
        ``[design.params]``: the keyword arguments of a design of one's own.
    design_tables : dict
        The top's parameter objects by sub-table (``[design.ultrasound]`` ...), a variant's
        changes applied.
    connectors : tuple of ConnectorSpec
        ``[[robot.sensors]]`` and ``[[robot.actuators]]`` (fpga_robotics.scenario.connectors).
    warnings : tuple of str
        Legal values that make a run meaningless, one line each naming the key path
        (fpga_robotics.scenario.sanity): printed before a run, errors with ``--strict``.
    """

    name: str
    description: str
    source: str
    seed: int
    data: dict
    world: dict
    camera: CameraConfig
    sim: SimConfig
    color_initial: str
    color_changes: tuple
    params: FollowTargetParams
    checks: dict
    overrides: tuple = ()
    foreign: "ForeignDesignFiles | None" = None
    top: str = "follow_target"
    design_tables: dict = field(default_factory=dict)
    design_params: dict = field(default_factory=dict)
    connectors: tuple = ()
    warnings: tuple = ()

    def color_at(self, t):
        """The colour select in force at simulated time ``t``."""
        color = self.color_initial
        for at, c in self.color_changes:
            if at <= t + SCHEDULE_SLACK:
                color = c
        return color

    def target_person(self):
        """``(scenario, index)``: this scenario with its people written out in ``data``
        (the world's default person where the file gives none, so that overrides can name
        ``people.0``) and the index of its target person (``target = true``, else the first
        person, as the world takes them), or None without one."""
        scenario = self
        if "people" not in self.data:
            data = copy.deepcopy(self.data)
            data["people"] = default_people(_check_world(self.world).room)
            scenario = _finish(data, self.source, self.overrides)
        people = scenario.data["people"]
        explicit = [i for i, p in enumerate(people) if p.get("target")]
        if explicit:
            return scenario, explicit[0]
        first = people[0] if people else None
        return scenario, 0 if first is not None and first.get("target") is None else None

    def with_overrides(self, overrides):
        """A new scenario: this one's data with more ``KEY=VALUE`` overrides applied."""
        data = copy.deepcopy(self.data)
        overrides = override_items(overrides)
        _drop_replaced_design(data, overrides)  # as loading with them does
        _apply_overrides(data, overrides)
        # The record lists each key once, with the value in force (a shadow's summary
        # names its own values, not the primary's it replaced).
        keys = [_override_key(o) for o in overrides]
        kept = tuple(
            o
            for o in self.overrides
            if not any(k == _override_key(o) or _override_key(o).startswith(k + ".") for k in keys)
        )
        return _finish(data, self.source, kept + overrides)


# Loading ------------------------------------------------------------------------------------


def _scenario_dir():
    return resources.files("fpga_robotics.scenario") / "shipped"


def shipped_scenarios():
    """Names → (path, description) of the scenarios shipped with the package, sorted."""
    out = {}
    for entry in sorted(_scenario_dir().iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".toml"):
            try:
                desc = tomllib.loads(entry.read_text()).get("description", "")
            except tomllib.TOMLDecodeError:
                desc = "(malformed)"
            out[entry.name[: -len(".toml")]] = (str(entry), desc)
    return out


def _resolve(name_or_path):
    text = str(name_or_path)
    if not text.strip():  # Path("") would be the current folder
        raise ScenarioError("the scenario is empty; give a shipped name or a .toml file")
    path = Path(text)
    if not (text.endswith(".toml") or "/" in text or "\\" in text):
        # A bare word: a file of that name here, else a shipped scenario.
        if path.is_file():
            return path
        shipped = shipped_scenarios()
        if text in shipped:
            return Path(shipped[text][0])
        if not path.exists():
            close = difflib.get_close_matches(text, shipped, n=3)
            hint = f" (did you mean {', '.join(close)}?)" if close else ""
            raise ScenarioError(
                f"unknown scenario {text!r}{hint}; shipped scenarios: {', '.join(shipped)} "
                f"(or give the path of a .toml file)"
            )
    if path.is_dir():
        raise ScenarioError(
            f"scenario {text!r} is a folder; give a .toml file in it or the "
            f"name of a shipped scenario"
        )
    if path.exists() and not path.is_file():
        raise ScenarioError(
            f"scenario file {text!r} is not a regular file (a device or pipe); give a .toml file"
        )
    if not path.exists():
        if path.suffix == ".toml" and path.name == text and path.stem in shipped_scenarios():
            raise ScenarioError(
                f"scenario file {text!r} does not exist here; for the shipped scenario "
                f"give its name: --scenario {path.stem}"
            )
        raise ScenarioError(f"scenario file {text!r} does not exist")
    return path


def _default_name(path):
    """The file's stem, made a safe file name (other characters become ``_``)."""
    name = re.sub(r"[^A-Za-z0-9_.-]", "_", path.stem).lstrip(".-")[:MAX_NAME_LENGTH]
    return name or "scenario"


def load_scenario(name_or_path, overrides=(), *, design_params=None):
    """Load a shipped scenario by name, or a TOML file by path, and apply overrides.

    Parameters
    ----------
    name_or_path : str or Path
        A shipped scenario's name (``follow_person``) or a ``.toml`` path.
    overrides : list of str
        ``"dotted.key=value"`` items; the value is parsed as TOML (bare words are strings).
        Array items are chosen by index, ``people.0.speed`` or ``people[0].speed``.
    design_params : dict, optional
        ``[design.params]`` values from Python, given to the design as they are (any
        Python value its signature takes), over the file's and under the overrides.

    Raises
    ------
    ScenarioError
        With one line that says what is wrong (unknown name, malformed TOML with its line,
        unknown key with close matches, invalid value, a run too large).
    """
    path = _resolve(name_or_path)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ScenarioError(
                f"scenario file {str(path)!r} is {size} bytes; a scenario is at "
                f"most {MAX_FILE_BYTES} bytes"
            )
        data = tomllib.loads(read_user_text(path))
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: malformed TOML: {exc}") from None
    except (OSError, NotTextError) as exc:
        raise ScenarioError(f"cannot read scenario file {path}: {exc}") from None
    _check_sections(data, path)
    if "name" not in data:
        data["name"] = _default_name(path)
    _fill_defaults(data)
    overrides = override_items(overrides)
    _drop_replaced_design(data, overrides)
    # After the replaced design's params are dropped: those given here are the new design's
    # (a Verilog one refuses them rather than running without them).
    if design_params:
        table = data["design"].setdefault("params", {})
        if isinstance(table, dict):  # else the file's error is said when it is resolved
            table.update(design_params)
    _apply_overrides(data, overrides)
    return _finish(data, str(path), overrides)


def override_items(overrides):
    """``overrides`` (a list of ``"KEY=VALUE"``, or None) as a tuple; ``ScenarioError`` for
    one string, which would otherwise be taken a character at a time."""
    if isinstance(overrides, str | bytes):
        raise ScenarioError(
            f'overrides must be a list of "KEY=VALUE" strings, got the string {overrides!r}; '
            f"write [{overrides!r}]"
        )
    return tuple(overrides or ())


def _drop_replaced_design(data, overrides):
    """An override that names another ``design.top`` (``run --design REF``) replaces the
    file's design: the file's tables of built-in designs that the new one does not take, and
    its ``variant``, go with the old design (its ``design.params`` stay, docs/your_design.md);
    so do a Verilog design's files and port map."""
    if not any(o.split("=", 1)[0].strip() == "design.top" for o in overrides):
        return
    probe = copy.deepcopy(data)
    _apply_overrides(probe, overrides)  # a bad override fails here as it would below
    design = data["design"]
    old, new = design.get("top", "follow_target"), probe["design"].get("top")
    if design.get("verilog") is not None and "top" not in design:
        old = None  # the file's own Verilog design (design.verilog)
    if new == old:
        return
    kept = TOPS[new].tables if isinstance(new, str) and new in TOPS else ()
    for key in (*_TOP_TABLES, "variant"):
        if key not in kept:
            design.pop(key, None)
    if isinstance(new, str) and new.startswith("verilog:"):
        # A Verilog design takes no parameters, and its files are the override's: the
        # file's own Verilog goes, its port map too where the overrides give another.
        design.pop("params", None)
        design.pop("verilog", None)
        if any(o.split("=", 1)[0].strip() == "design.ports" for o in overrides):
            design.pop("ports", None)
    elif old is None or (isinstance(old, str) and old.startswith("verilog:")):
        # An Amaranth design in place of the file's Verilog one: its files go.
        design.pop("verilog", None)
        design.pop("ports", None)


def _finish(data, source, overrides):
    # An override may have replaced a whole table: check the sections again, then fill in
    # the keys it left out with their defaults (as a file that gives the table would).
    _check_sections(data, None)
    _fill_defaults(data)
    scenario = _build(data, source, overrides)
    # After the checks of every value: a bad one is the first thing to say.
    _refuse_unread_overrides(data, [_override_key(o) for o in overrides])
    return scenario


def _check_sections(data, path):
    where = f"{path}: " if path is not None else ""
    known = set(_TOP_KEYS) | set(WORLD_SECTIONS) | set(_APP_SECTIONS)
    for key in data:
        if key not in known:
            raise ScenarioError(f"{where}unknown top-level key {key!r}{_close(key, known)}")
    models = _section_models()
    for section in _APP_SECTIONS:
        value = data.get(section, {})
        if not isinstance(value, dict):
            raise ScenarioError(
                f"{where}{section} must be a table ([{section}] in a file, --set "
                f"{section}.KEY=VALUE on the command line), got {value!r}"
            )
        model = models[section]
        _check_subtables(value, DEFAULTS.get(section, {}), section, where)
        for key in value:
            if key not in model.key_names():
                raise ScenarioError(where + model.unknown_key(f"{section}.{key}", key))


def _check_subtables(table, defaults, section, where):
    """A section's sub-tables (``camera.ov7670``) are tables of known keys."""
    for key, default in defaults.items():
        if isinstance(default, dict) and key in table:
            sub = table[key]
            if not isinstance(sub, dict):
                raise ScenarioError(
                    f"{where}{section}.{key} must be a table ([{section}.{key}] "
                    f"in a file), got {sub!r}"
                )
            for k in sub:
                if k not in default:
                    raise ScenarioError(
                        f"{where}unknown key {section}.{key}.{k}"
                        f"{_close(k, default, f'{section}.{key}')}"
                    )


def _fill_defaults(data):
    for section, defaults in DEFAULTS.items():
        table = data.setdefault(section, {})
        for key, value in defaults.items():
            if key not in table and value is not None:
                table[key] = copy.deepcopy(value)
            elif isinstance(value, dict) and isinstance(table[key], dict):
                for k, v in value.items():  # a sub-table's keys the file leaves out
                    table[key].setdefault(k, copy.deepcopy(v))
    data.setdefault("design", {})
    data.setdefault("checks", {})
    data.setdefault("description", "")
    data.setdefault("seed", 0)


def _close(key, candidates, prefix=None):
    close = difflib.get_close_matches(key, list(candidates), n=3, cutoff=0.5)
    if not close:
        return ""
    names = [f"{prefix}.{c}" if prefix else c for c in close]
    return f" (did you mean {', '.join(names)}?)"


# Overrides ----------------------------------------------------------------------------------


def _parse_value(text):
    """A TOML value (``12``, ``0.5``, ``true``, ``"red"``, ``[1, 2]``); bare words are strings."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text.strip()


def _known_paths(data):
    """Every dotted key the data has, plus the application's optional keys."""
    out = []

    def walk(prefix, value):
        if isinstance(value, dict):
            for k, v in value.items():
                walk(f"{prefix}.{k}" if prefix else k, v)
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for i, v in enumerate(value):
                walk(f"{prefix}.{i}", v)
        if prefix:
            out.append(prefix)

    walk("", data)
    out += list(WORLD_SECTIONS)
    out += [f"design.{k}" for k in design_keys().key_names()]
    out += [f"checks.{k}" for k in CHECKS]
    out += [f"{s}.{k}" for s, d in DEFAULTS.items() for k in d]
    return sorted(set(out))


def _override_key(item):
    """The dotted key an override sets (``people[0].speed`` as ``people.0.speed``)."""
    return re.sub(r"\[(\d+)\]", r".\1", item.partition("=")[0].strip())


def _apply_overrides(data, overrides):
    for item in overrides:
        # '=3' has no key: say what --set wants, not "unknown scenario key ''".
        if not isinstance(item, str) or "=" not in item or not item.partition("=")[0].strip():
            raise ScenarioError(f"--set needs KEY=VALUE (e.g. robot.mass=12), got {item!r}")
        key, text = item.split("=", 1)
        key = key.strip()
        value = _parse_value(text)
        # people[0].speed, as the world's messages write it, is people.0.speed.
        _set_path(data, _override_key(item), value, key)


#: The ``[camera]`` keys only the 3D renderer reads (docs/render3d.md).
_RENDER3D_KEYS = ("shadows", "shadow_size", "textures", "floor", "shine", "lamps")


def _refuse_unread_overrides(data, keys):
    """An override of a value the scenario as set never reads would change nothing, silently:
    ``ScenarioError`` saying what does set it."""
    lighting = data.get("lighting")
    if isinstance(lighting, dict) and lighting.get("keyframes"):
        for key in ("lighting.ambient", "lighting.intensity"):
            if key in keys:
                raise ScenarioError(
                    f"{key} is not used: the scenario's lighting.keyframes set the light over "
                    f"time; set lighting.keyframes=[] as well for a constant light, or change "
                    f"the keyframes"
                )
    camera = data.get("camera")
    sensor = camera.get("sensor", "plain") if isinstance(camera, dict) else "plain"
    if sensor == "ov7670" and "camera.noise_std" in keys:
        raise ScenarioError(
            'camera.noise_std is not used: with camera.sensor = "ov7670" the sensor model '
            "makes the noise (its [camera.ov7670] shot and read noise)"
        )
    if sensor != "ov7670":
        for key in keys:
            if key == "camera.ov7670" or key.startswith("camera.ov7670."):
                raise ScenarioError(
                    f'{key} is not used: camera.sensor is "{sensor}"; set '
                    f"camera.sensor=ov7670 as well for the sensor model"
                )
    renderer = camera.get("renderer", "raster") if isinstance(camera, dict) else "raster"
    if renderer != "mujoco":
        for key in keys:
            section, _, rest = key.partition(".")
            if section == "camera" and rest.split(".")[0] in _RENDER3D_KEYS:
                raise ScenarioError(
                    f'{key} is not used: camera.renderer is "{renderer}" and only the 3D '
                    f"renderer reads it; set camera.renderer=mujoco as well (docs/render3d.md)"
                )


def _set_path(data, key, value, shown):
    parts = key.split(".")
    node = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        here = ".".join(parts[: i + 1])
        if isinstance(node, list):
            if not node:
                raise ScenarioError(
                    f"unknown key {shown!r}: {'.'.join(parts[:i])} is an empty list; set it "
                    f"whole: --set '{'.'.join(parts[:i])}=[...]' (a TOML array)"
                )
            if not part.isdigit() or int(part) >= len(node):
                raise ScenarioError(
                    f"unknown key {shown!r}: {'.'.join(parts[:i])} is a list of {len(node)} "
                    f"item(s), index it with 0..{len(node) - 1}"
                )
            part = int(part)
            if last:
                node[part] = _coerce(node[part], value)
                return
            node = node[part]
            continue
        if not isinstance(node, dict):
            raise ScenarioError(f"unknown key {shown!r}: {'.'.join(parts[:i])} is not a table")
        # Inside the world's sections any key may be set: the world validates the result
        # (with close matches) when the scenario is built.
        in_world = parts[0] in WORLD_SECTIONS
        if i == 0 and in_world and part not in data and parts[0] != "people" and not last:
            node[part] = {}
        optional = _optional_keys(parts[:i])
        if not last and part not in node and here in _WORLD_ARRAYS and parts[i + 1].isdigit():
            # A list the world may hold (room.furniture) but this scenario does not.
            raise ScenarioError(
                f"unknown key {shown!r}: the scenario has no {here} to index; set it "
                f"whole: --set '{here}=[...]' (a TOML array)"
            )
        if part not in node and part not in optional and not (in_world and last):
            if parts[:i] == ["design"] and part in ("width", "height"):
                raise ScenarioError(
                    f"design.{part} comes from camera.resolution; "
                    f"set camera.resolution=WxH (or --resolution) instead"
                )
            raise ScenarioError(_unknown_key_message(data, key, here, shown))
        if last:
            node[part] = _coerce(node.get(part), value)
            return
        if (
            part not in node
            and parts[:i] == ["design"]
            and part in (*_TOP_TABLES, "params", "defines")
        ):
            node[part] = {}  # a design parameter table the file does not give
        node = node[part]


#: The world's arrays inside a section (``room.furniture``, ``robot.sensors``,
#: ``lighting.keyframes`` ...): a scenario may leave one out, and ``--set`` then cannot
#: index it.
_WORLD_ARRAYS = frozenset(path for path in WORLD_KEY_MODELS if "." in path) | {
    "robot.sensors",
    "robot.actuators",
    "lighting.keyframes",
}


class _AnyName:
    """Every name: the keys of ``design.params`` (and a Verilog design's ``design.defines``)
    are the design's own (checked against its signature when it is resolved)."""

    def __contains__(self, name):
        return True


def _optional_keys(parents):
    """Keys that may be set although the file does not give them."""
    if parents in (["design", "params"], ["design", "defines"]):
        return _AnyName()
    if len(parents) == 2 and parents[0] == "design" and parents[1] in _TOP_TABLES:
        return table_fields(parents[1])
    if len(parents) != 1:
        return ()
    section = parents[0]
    if section == "design":
        return design_keys().key_names()
    if section == "checks":
        return CHECKS
    return tuple(DEFAULTS.get(section, ()))


def _unknown_key_message(data, key, here, shown):
    depth = key.count(".")
    paths = [p for p in _known_paths(data) if p.count(".") == depth]
    close = difflib.get_close_matches(key, paths, n=4, cutoff=0.6)
    if not close:
        # Suggest the siblings of the deepest known parent.
        parent = here.rsplit(".", 1)[0] if "." in here else ""
        close = [p for p in paths if parent and p.startswith(parent + ".")][:10]
    hint = f"; close matches: {', '.join(close)}" if close else ""
    return f"unknown scenario key {shown!r}{hint}"


def _coerce(old, value):
    # An int where the scenario had a float is a float (``--set sim.duration=10``).
    if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value


# Validation ---------------------------------------------------------------------------------


def _keys(model, table, prefix):
    """The table's keys validated by their model; a ``ScenarioError`` naming the key."""
    return validate(model, table, prefix, ScenarioError)


def _check(key_type, value, path):
    """``value`` checked by one key type (for a bound that depends on other keys)."""
    try:
        return check_of(key_type)(value)
    except PydanticCustomError as exc:
        raise ScenarioError(f"{path}{exc.context.get('sub', '')} {exc.message()}") from None


def _floor(x, digits):
    """``x`` rounded down to ``digits`` decimals: a printed limit a user can type."""
    scale = 10**digits
    return math.floor(x * scale) / scale


def _check_world(world):
    """Validate the world's sections now, so that a bad value is reported at load time;
    returns the parsed ``WorldConfig``."""
    try:
        # Building it also finds placement errors (a robot starting inside a person).
        return World.from_config(copy.deepcopy(world), 0).config
    except WorldConfigError as exc:
        raise ScenarioError(str(exc)) from None


def _check_name(name):
    if not isinstance(name, str):
        raise ScenarioError(f"name must be a string, got {name!r}")
    if not (len(name) <= MAX_NAME_LENGTH and _NAME.fullmatch(name)):
        raise ScenarioError(
            f"name {name!r} cannot be a file name (a recording is saved as runs/<name>.rrd): "
            f"use at most {MAX_NAME_LENGTH} ASCII letters, digits, '_', '-' and '.', "
            f"starting with a letter, a digit or '_'"
        )
    return name


def _camera(data):
    k = _keys(CameraKeys, data["camera"], "camera")
    width, height = parse_resolution(k.resolution, "camera.resolution")
    if not (
        WIDTH_RANGE[0] <= width <= WIDTH_RANGE[1] and HEIGHT_RANGE[0] <= height <= HEIGHT_RANGE[1]
    ):
        raise ScenarioError(
            f"camera.resolution {width}x{height}: the width must be {WIDTH_RANGE[0]}.."
            f"{WIDTH_RANGE[1]} and the height {HEIGHT_RANGE[0]}..{HEIGHT_RANGE[1]} pixels "
            f"(the design's limits)"
        )
    render3d = Render3DOptions(
        shadows=k.shadows,
        shadow_size=k.shadow_size,
        textures=k.textures,
        floor=k.floor,
        shine=k.shine,
        lamps=tuple(Lamp(**lamp.model_dump()) for lamp in k.lamps),
        seed=data.get("seed", 0),
    )
    return CameraConfig(
        width=width,
        height=height,
        fps=k.fps,
        hfov=k.hfov,
        mount_height=k.mount_height,
        mount_forward=k.mount_forward,
        tilt=k.tilt,
        noise_std=k.noise_std,
        yaw_offset=math.radians(k.yaw_offset_deg),
        exposure_drift=k.exposure_drift,
        sensor=k.sensor,
        ov7670=_sensor_params(data["camera"]["ov7670"]),
        renderer=k.renderer,
        render3d=render3d,
    )


def _sensor_params(table):
    """``[camera.ov7670]`` (its keys from ``sim.sensor.PARAMS``)."""
    values = dict(_keys(ov7670_keys(), table, "camera.ov7670"))
    (lo, hi), (fast_lo, fast_hi) = values["aec_window"], values["aec_fast_zone"]
    if not fast_lo <= lo < hi <= fast_hi:
        raise ScenarioError(
            f"camera.ov7670.aec_window {[lo, hi]} must lie inside "
            f"camera.ov7670.aec_fast_zone {[fast_lo, fast_hi]}"
        )
    return OV7670Params.from_dict(values)


def _steepest_slope(room):
    """``(slope, text)``: the steepest terrain patch's slope (rad, 0 without one) and the words
    that name it in a message. A camera on a patch pitches by up to its slope
    (``sim.world.terrain.slope_pitch``), so its tilt may use only the room that leaves."""
    patch = max(room.terrain, key=lambda p: p.slope, default=None)
    if patch is None or patch.slope == 0.0:
        return 0.0, ""
    return patch.slope, (
        f" and the {math.degrees(patch.slope):g} deg slope of room.terrain {patch.name!r}"
    )


def _check_camera_geometry(camera, world):
    """The mount and the field of view the renderer will be asked to draw: between floor and
    ceiling, and no ray looking straight up or down (``sim.camera.max_tilt``), even on the
    steepest terrain patch."""
    ceiling = world.room.height
    if camera.mount_height is not None and not camera.mount_height < ceiling:
        raise ScenarioError(
            f"camera.mount_height must be below the ceiling (room.height = "
            f"{ceiling:g} m), got {camera.mount_height:g}"
        )
    slope, on_slope = _steepest_slope(world.room)
    w, h, hfov = camera.width, camera.height, camera.hfov
    vfov = vertical_fov(w, h, hfov)
    limit = max_tilt(w, h, hfov) - slope
    if limit < 0:
        raise ScenarioError(
            f"camera.hfov must be at most {_floor(max_hfov(w, h, slope), 4)} rad at "
            f"camera.resolution {w}x{h}{on_slope}, got {hfov:g} (a vertical field of view of "
            f"{vfov:.3f} rad: the top and bottom rows would look straight up or down)"
        )
    if camera.tilt is not None:
        tilt, key, shown, unit = camera.tilt, "camera.tilt", _floor(limit, 4), "rad"
    else:
        tilt, key, unit = world.robot.spec.camera_tilt, "robot.camera_tilt_deg", "deg"
        shown = _floor(math.degrees(limit), 2)
    if abs(tilt) > limit:
        got = tilt if unit == "rad" else math.degrees(tilt)
        raise ScenarioError(
            f"|{key}| must be at most {shown} {unit} with camera.hfov {hfov:g} rad at "
            f"{w}x{h}{on_slope} (vertical field of view {vfov:.3f} rad; beyond it rows would "
            f"look straight up or down), got {got:g}"
        )


def _check_further_cameras(connectors, sim, world):
    """Each ``[[robot.sensors]]`` camera, as the body camera: between floor and ceiling, its
    field of view one the renderer draws (even on the steepest terrain patch), and at most
    one frame a physics step (the rig captures at physics steps); its ``on`` a servo of the
    scenario, its ``target`` one of its people."""
    ceiling, dt = world.room.height, sim.physics_dt
    slope, on_slope = _steepest_slope(world.room)
    servos = {spec.name for spec in connectors if spec.kind == "servo"}
    people = [person.name for person in world.people]
    for spec in connectors:
        if spec.kind != "camera":
            continue
        where, p = f"camera {spec.name!r}", spec.params
        if p.on is not None and p.on not in servos:
            raise ScenarioError(
                f"{where}: on = {p.on!r} names no servo; declare [[robot.actuators]] "
                f'kind = "servo", name = {p.on!r}, or mount the camera on the body (no on)'
            )
        if p.target is not None and p.target not in people:
            among = f"the people: {', '.join(people)}" if people else "the room has no people"
            raise ScenarioError(f"{where}: target = {p.target!r} names no person; {among}")
        height, fps = spec.mount.height, spec.params.fps
        if height <= 0:
            raise ScenarioError(
                f"{spec.where} (camera {spec.name!r}): give its height above the floor "
                "(height = m, > 0)"
            )
        if height >= ceiling:
            raise ScenarioError(
                f"{spec.where}.height {height:g} m must be below the ceiling (room.height "
                f"{ceiling:g} m)"
            )
        _check_further_field_of_view(spec, slope, on_slope)
        if dt > spec.params.frame_period:
            raise ScenarioError(
                f"{spec.where}.fps {fps:g} is more than one frame a physics step "
                f"(sim.physics_dt {dt:g} s: at most {1 / dt:g}); lower it or shorten "
                "sim.physics_dt"
            )


def _check_further_field_of_view(spec, slope, on_slope):
    """A further camera's ``hfov_deg`` and ``tilt_deg`` against its resolution, as
    ``_check_camera_geometry`` checks the body camera's."""
    p = spec.params
    w, h = p.width, p.height
    vfov = vertical_fov(w, h, p.hfov)
    limit = max_tilt(w, h, p.hfov) - slope
    if limit < 0:
        widest = _floor(math.degrees(max_hfov(w, h, slope)), 2)
        raise ScenarioError(
            f"{spec.where}.hfov_deg must be at most {widest} deg at its resolution "
            f"{w}x{h}{on_slope}, got {math.degrees(p.hfov):g} (a "
            f"vertical field of view of {math.degrees(vfov):.1f} deg: the top and bottom rows "
            "would look straight up or down)"
        )
    if abs(p.tilt) > limit:
        raise ScenarioError(
            f"|{spec.where}.tilt_deg| must be at most {_floor(math.degrees(limit), 2)} deg "
            f"with its hfov_deg {math.degrees(p.hfov):g} at {w}x{h}{on_slope} (vertical field "
            f"of view {math.degrees(vfov):.1f} deg; beyond it rows would look straight up or "
            f"down), got {math.degrees(p.tilt):g}"
        )


def _sim(data, camera):
    k = _keys(SimKeys, data["sim"], "sim")
    period = camera.frame_period
    if isinstance(k.physics_dt, int | float) and k.physics_dt > period:  # names both keys
        raise ScenarioError(
            f"sim.physics_dt {k.physics_dt:g} s is longer than a camera frame period "
            f"(1 / camera.fps {camera.fps:g} = {period:g} s); a physics step must be at most "
            f"one frame: set sim.physics_dt to {period:g} or less, or lower camera.fps"
        )
    # The physics step: at most one frame period (a bound that depends on camera.fps).
    step = Number(
        ge=1e-5,
        le=period,
        unit="s",
        style="scenario",
        note=" (one camera frame period, 1 / camera.fps)",
    )
    dt = _check(step, k.physics_dt, "sim.physics_dt")
    duration = k.duration
    # None: one frame period, or REAL_CLOCK_ACTUATION_DELAY (_resolve_timing).
    config = SimConfig(
        duration=duration,
        physics_dt=dt,
        actuation_delay=k.actuation_delay,
        timing=k.timing,
        clock_hz=DEFAULT_CLOCK_HZ if k.clock_hz is None else k.clock_hz,
    )
    steps = max(1, round(duration / dt))  # as the closed loop counts them
    if steps > MAX_PHYSICS_STEPS:
        raise ScenarioError(
            f"sim.duration {duration:g} s / sim.physics_dt {dt:g} s = {steps} physics steps; "
            f"the limit is {MAX_PHYSICS_STEPS}: shorten sim.duration or lengthen "
            f"sim.physics_dt"
        )
    frames = frame_count(steps, period, dt)
    if frames > MAX_FRAMES:
        raise ScenarioError(
            f"sim.duration {duration:g} s at camera.fps {camera.fps:g} = {frames} camera "
            f"frames; the limit is {MAX_FRAMES}: shorten sim.duration or lower camera.fps"
        )
    return config


def _color_changes(data):
    k = _keys(ColorKeys, data["color"], "color")
    return k.initial, k.changes


def _foreign(design, source):
    """``design.verilog`` and ``design.ports`` (popped from ``design``), or ``design.top =
    "verilog:FILES"`` with ``ports``: a ``ForeignDesignFiles`` or None; relative paths from
    the scenario file's folder."""
    verilog, ports = design.pop("verilog", None), design.pop("ports", None)
    defines = design.pop("defines", None)
    top = design.get("top")
    if isinstance(top, str) and top.startswith("verilog:"):
        if verilog is not None:
            raise ScenarioError(
                'give the Verilog files once: design.top = "verilog:..." or '
                "design.verilog, not both"
            )
        verilog = [f for f in top[len("verilog:") :].split(",") if f.strip()]
        if ports is None:
            raise ScenarioError(
                f'design.top = {top!r} needs design.ports = "ports.toml" '
                f"(the design's port map, docs/foreign.md)"
            )
    elif top is not None and verilog is not None:
        # Two designs named in the file: which one would run?
        raise ScenarioError(
            f"design.top = {top!r} and design.verilog name two designs: give one (the "
            f'Verilog one as design.verilog, or design.top = "verilog:..."; docs/foreign.md)'
        )
    if verilog is None and ports is None:
        if defines is not None:
            raise ScenarioError(
                "design.defines sets `define macros of a Verilog design (design.verilog)"
            )
        return None
    if verilog is None:
        raise ScenarioError('design.ports goes with design.verilog = ["top.v", ...]')
    if ports is None:
        raise ScenarioError(
            'design.verilog needs design.ports = "ports.toml" (the design\'s '
            "port map, docs/foreign.md)"
        )
    if isinstance(verilog, str):
        verilog = [verilog]
    if not (
        isinstance(verilog, list)
        and verilog
        and all(isinstance(f, str) and f.strip() for f in verilog)
    ):
        raise ScenarioError(
            f"design.verilog must be an array of Verilog file paths, got {verilog!r}"
        )
    if not (isinstance(ports, str) and ports.strip()):
        raise ScenarioError(f"design.ports must be the path of a port map (.toml), got {ports!r}")
    base = Path(source).parent if source else Path(".")

    def existing(key, text):
        path = Path(text).expanduser()
        path = path if path.is_absolute() else base / path
        if not path.is_file():
            raise ScenarioError(f"design.{key}: no file {text!r} (looked for {str(path)!r})")
        return str(path)

    return ForeignDesignFiles(
        tuple(existing("verilog", f) for f in verilog),
        existing("ports", ports),
        _verilog_overrides(design.get("params", {}), defines),
    )


def _verilog_overrides(params, defines):
    """``[design.params]`` and ``[design.defines]`` of a Verilog design as a
    ``VerilogOverrides`` (None without either); the names are checked against the design
    when it is read."""
    if not params and not defines:
        return None
    for key, table in (("params", params), ("defines", defines or {})):
        if not isinstance(table, dict):
            raise ScenarioError(
                f"design.{key} must be a table ([design.{key}] in a file, "
                f"--set design.{key}.NAME=VALUE), got {table!r}"
            )
    try:
        return VerilogOverrides.of(params, defines)
    except PortMapError as exc:
        text = (
            str(exc).replace("--param ", "design.params.").replace("--define ", "design.defines.")
        )
        raise ScenarioError(text) from None


def _design(data, width, height):
    design = dict(data["design"])
    for key in _FOREIGN_KEYS + _TOP_DESIGN_KEYS:
        design.pop(key, None)
    preset = design.pop("preset", None)
    _keys(design_keys(), design, "design")  # the types; FollowTargetParams the ranges
    values = {}
    if preset is not None:
        if preset not in PRESETS:
            raise ScenarioError(
                f"design.preset must be one of {', '.join(map(repr, PRESETS))}, got {preset!r}"
            )
        # The preset first, the scenario's other design keys on top.
        values = preset_values(preset, width, height)
    values.update(design)
    try:
        return FollowTargetParams(width=width, height=height, **values)
    except (TypeError, ValueError) as exc:
        message = str(exc)
        field = re.match(r"\w+", message)
        if field and field.group() in design:  # "kp_shift must be <= 15, got 99"
            raise ScenarioError(f"design.{message}") from None
        raise ScenarioError(
            f"invalid design parameters with camera.resolution {width}x{height}: {message}"
        ) from None


def _top(design, source):
    """``design.top``, its parameter tables (a ``design.variant`` applied first) and
    ``design.params``; a design of one's own is resolved here (designs/reference.py), its
    reference made independent of the current folder."""
    top = design.get("top", "follow_target")
    params = design.get("params", {})
    if not isinstance(params, dict):
        raise ScenarioError(
            f"design.params must be a table ([design.params] in a file, "
            f"--set design.params.NAME=VALUE), got {params!r}"
        )
    # The scenario's own Verilog (design.verilog) when it names no other design.top.
    verilog = design.get("verilog") is not None and "top" not in design
    if verilog or (isinstance(top, str) and top.startswith("verilog:")):
        top = "follow_target"  # the design is the scenario's foreign one (design.ports)
        params = {}  # the Verilog design's (ForeignDesignFiles.overrides)
        if not verilog:
            # design.top = "verilog:..." replaces the scenario's design, as run --design
            # does: the built-in design's tables (a line_track's [design.line]) go with it.
            return top, {}, {}
    if not isinstance(top, str) or top not in TOPS:
        given = [k for k in _TOP_TABLES if design.get(k) is not None]
        if given:
            raise ScenarioError(
                f"design.{given[0]} is a table of a built-in design; a "
                f"design of your own takes design.params"
            )
        if design.get("variant") is not None:
            raise ScenarioError(
                "design.variant names a buggy variant of a built-in design; "
                f"design.top = {top!r} has none"
            )
        base = Path(source).parent if source else None
        try:
            spec = resolve_design(top, params, base=base)
        except DesignError as exc:
            raise ScenarioError(str(exc)) from None
        return spec.reference, {}, dict(spec.params)
    if params:
        raise ScenarioError(
            f"design.params: the built-in design {top!r} takes its "
            f"parameters from [design] and its own tables "
            f"({', '.join(TOPS[top].tables) or 'none'}), not design.params"
        )
    spec = TOPS[top]
    tables = {}
    for key in _TOP_TABLES:
        value = design.get(key)
        if value is None:
            continue
        if key not in spec.tables:
            raise ScenarioError(
                f"design.{key} is a table of another design; design.top = "
                f"{top!r} takes: {', '.join(spec.tables) or 'none'}"
            )
        if not isinstance(value, dict):
            raise ScenarioError(
                f"design.{key} must be a table ([design.{key}] in a file), got {value!r}"
            )
        tables[key] = dict(value)
    try:
        return top, design_tables(spec, tables, design.get("variant")), {}
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None


def _check_follow_target_keys_read(design, top, design_params):
    """FollowTarget's ``[design]`` keys (and ``preset``) on a design that reads none: no
    FollowTarget inside and no camera whose checks hold it to their law (docs/your_design.md)
    would run the scenario as if they were not given, so they are an error, as ``export``
    makes them."""
    given = [k for k in design if k not in _FOREIGN_KEYS + _TOP_DESIGN_KEYS]
    if not given:
        return
    spec = resolve_design(top, design_params)
    if spec.top.camera or spec.top.takes_follow_target_params:
        return
    readers = [t.name for t in TOPS.values() if t.camera or t.takes_follow_target_params]
    keys = ", ".join(f"design.{k}" for k in given)
    raise ScenarioError(
        f"{keys} {'applies' if len(given) == 1 else 'apply'} to a design with FollowTarget "
        f"or a camera ({', '.join(readers)}), not to design.top = {spec.top.name!r}, which "
        "reads none of them"
    )


def _run_clock(design, sim, connectors):
    """``[design]`` with the tables of a built-in design that count time on the run's clock
    (``[design.ultrasound]``, ``[design.uart]``: a ``clock_hz`` field) made to agree with
    it: a key left out takes ``sim.clock_hz`` (and a UART's ``baud`` the ``lidar_uart``
    table's); a different value is refused, since the design would time everything wrong
    (an echo's width read as another distance, every bit of a byte at another length)."""
    top = design.get("top")
    if not (isinstance(top, str) and top in TOPS):
        return design
    sensors = [c for c in connectors if c.role == "sensor"]
    links = [i for i, c in enumerate(sensors) if c.kind == "lidar_uart"]
    out = dict(design)
    for key in TOPS[top].tables:
        table, fields = design.get(key, {}), table_fields(key)
        if not isinstance(table, dict) or "clock_hz" not in fields:
            continue
        run = {"clock_hz": (round(sim.clock_hz), "sim.clock_hz")}
        if "baud" in fields and links:
            run["baud"] = (sensors[links[0]].params.baud, f"robot.sensors[{links[0]}].baud")
        for name, (value, source) in run.items():
            given = table.get(name, value)
            if isinstance(given, int | float) and not isinstance(given, bool) and given != value:
                raise ScenarioError(
                    f"design.{key}.{name} {given:.15g} does not match {source} {value}; leave "
                    f"design.{key}.{name} out to take it"
                )
        taken = {name: value for name, (value, _) in run.items() if name not in table}
        if not taken:
            continue
        # Say where a value the user did not write comes from.
        try:
            table_class(key)(**{**table, **taken})
        except ParamError as exc:
            sources = ", ".join(f"{name} is {run[name][1]}" for name in taken)
            raise ScenarioError(f"design.{key}: {exc} ({sources})") from None
        except TypeError:
            pass  # a value of the wrong type or name: design_tables says so
        out[key] = {**table, **taken}
    return out


def _connectors(world):
    """``robot.sensors`` / ``robot.actuators``, taken out of the world's ``robot`` table."""
    robot = world.get("robot")
    if not isinstance(robot, dict):
        return ()
    try:
        return parse_connectors(robot)
    except ConnectorError as exc:
        raise ScenarioError(str(exc)) from None


def _check_connectors_in_run(connectors, sim, room):
    """Each connector table against the run's clock and the room (``Connector.check_run``)."""
    counts = {}
    for spec in connectors:
        index = counts[spec.role] = counts.get(spec.role, -1) + 1
        where = f"robot.{spec.role}s[{index}]"
        try:
            CONNECTORS[spec.kind].check_run(spec.params, spec.mount, where, sim, room)
        except ConnectorError as exc:
            raise ScenarioError(str(exc)) from None


def _resolve_timing(sim, camera, top, design_params, connectors, foreign):
    """``sim.timing = "auto"`` made definite; a design or connector with pins of its own
    needs real-clock timing."""
    # Every built-in design but the camera-only follow_target has pins of its own, unless
    # it has frame-level channels for further cameras; cameras and servos act once a frame.
    # A design of one's own streams only its camera frame by frame: any connector needs pins.
    own = top not in TOPS
    frame_level = not own and bool(TOPS[top].frame_channels)
    pins = [
        f"the {c.kind} connector"
        for c in connectors
        if own or not getattr(CONNECTORS[c.kind], "frame_level", False)
    ]
    if own:
        reason = resolve_design(top, design_params).real_clock_reason()
        if reason is not None:
            pins.insert(0, f"design.top = {top!r} ({reason})")
    elif top != "follow_target" and not frame_level:
        pins.insert(0, f"design.top = {top!r}")
    if foreign is not None:
        # A port map that binds connectors (or has no camera) is a design with pins.
        try:
            port_map = load_port_map(foreign.ports)
        except PortMapError as exc:
            raise ScenarioError(f"design.ports: {exc}") from None
        if port_map.connectors:
            pins.insert(0, f"the port map's [connectors.{next(iter(port_map.connectors))}]")
        elif port_map.extra_outputs:
            pins.insert(0, "the port map's [extra_outputs]")
        elif not port_map.has_pixels:
            pins.insert(0, "a port map without pixels")
    timing = sim.timing
    if timing == "auto":
        timing = "real_clock" if pins else "compressed"
    elif timing == "compressed" and pins:
        raise ScenarioError(
            f'sim.timing = "compressed" runs the design only while pixels '
            f'flow; {pins[0]} needs sim.timing = "real_clock" (or "auto")'
        )
    delay = sim.actuation_delay
    if delay is None:
        delay = REAL_CLOCK_ACTUATION_DELAY if timing == "real_clock" else camera.frame_period
    return replace(sim, timing=timing, actuation_delay=delay)


def _clock_warnings(data, sim, top):
    """A warning when the scenario gives ``sim.clock_hz`` (its file or an override) and its
    run does not read it: compressed timing clocks a built-in or Verilog design only while
    its pixels flow, at no rate (a design of one's own reads it there: a frame's budget of
    edges, loop/pin_frames.py). A warning, not an error: a file's clock may be for the design
    an override replaced, and a campaign's ``set`` reaches rows of either timing."""
    if data["sim"].get("clock_hz") is None or sim.timing != "compressed" or top not in TOPS:
        return ()
    warning = (
        f"sim.clock_hz {sim.clock_hz:g} changes nothing: the design runs in compressed "
        f"timing, clocked only while the pixels flow, at no clock rate; set sim.timing = "
        f'"real_clock" to run it on that clock, or leave sim.clock_hz out'
    )
    return (warning,)


def _checks(data):
    _keys(checks_keys(), data["checks"], "checks")
    return dict(data["checks"])


def _build(data, source, overrides):
    name = _check_name(data.get("name"))
    top_keys = _keys(TopKeys, {k: data[k] for k in ("description", "seed") if k in data}, "")
    description, seed = top_keys.description, data.get("seed", 0)
    for section in WORLD_SECTIONS:
        if section in data and not isinstance(data[section], (dict, list)):
            if section == "people":
                raise ScenarioError(
                    f"people must be an array of tables ([[people]] in a file, --set "
                    f"'people=[{{waypoints = [[4, 3]]}}]'), got {data[section]!r}"
                )
            raise ScenarioError(f"[{section}] must be a table, got {data[section]!r}")

    camera = _camera(data)
    sim = _sim(data, camera)
    initial, changes = _color_changes(data)
    params = _design(data, camera.width, camera.height)
    foreign = _foreign(dict(data["design"]), source)
    world = {s: copy.deepcopy(data[s]) for s in WORLD_SECTIONS if s in data}
    connectors = _connectors(world)
    top, tables, design_params = _top(_run_clock(data["design"], sim, connectors), source)
    if foreign is None:
        _check_follow_target_keys_read(data["design"], top, design_params)
    checks = _checks(data)
    sim = _resolve_timing(sim, camera, top, design_params, connectors, foreign)
    world_config = _check_world(world)
    _check_camera_geometry(camera, world_config)
    _check_connectors_in_run(connectors, sim, world_config.room)
    _check_further_cameras(connectors, sim, world_config)
    return Scenario(
        name=name,
        description=description,
        source=source,
        seed=seed,
        data=data,
        world=world,
        camera=camera,
        sim=sim,
        color_initial=initial,
        color_changes=changes,
        params=params,
        checks=checks,
        overrides=tuple(overrides),
        foreign=foreign,
        top=top,
        design_tables=tables,
        design_params=design_params,
        connectors=connectors,
        warnings=(
            *scenario_warnings(world_config, checks),
            *_clock_warnings(data, sim, top),
        ),
    )
