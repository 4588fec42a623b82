"""Scenarios as data: load a TOML file, fill defaults, apply ``--set`` overrides, validate.

A scenario file has two kinds of sections. The world's sections (``room``, ``robot``,
``people``, ``lighting``) are passed unchanged to ``World.from_config``, which validates them
(see docs/scenarios.md). The application's sections are validated here:

- ``[sim]``: ``duration`` (s), ``physics_dt`` (s), ``actuation_delay`` (s, default one frame
  period);
- ``[camera]``: ``resolution`` ("WxH"), ``fps``, ``hfov`` (rad), ``mount_height`` (m),
  ``mount_forward`` (m ahead of the robot's centre), ``tilt`` (rad, up positive), ``noise_std``;
- ``[color]``: ``initial`` colour and ``changes = [{at = seconds, color = "..."}, ...]``;
- ``[design]``: any ``FollowTargetParams`` field except ``width``/``height`` (those come from
  the camera resolution);
- ``[checks]``: the pass criteria of the scenario (see ``fpga_robotics.summary.CHECKS``).

Top-level keys: ``name``, ``description``, ``seed`` (default seed of a run).
"""

import copy
import difflib
import math
import tomllib
from dataclasses import dataclass, fields
from importlib import resources
from pathlib import Path

from .errors import UsageError
from .hw.params import FollowTargetParams
from .hw.pixel import COLOR_SELECT
from .sim.world.config import WORLD_SECTIONS
from .summary import CHECKS

__all__ = [
    "WORLD_SECTIONS",
    "CameraConfig",
    "Scenario",
    "ScenarioError",
    "SimConfig",
    "load_scenario",
    "parse_resolution",
    "shipped_scenarios",
]

_TOP_KEYS = ("name", "description", "seed")
_DESIGN_KEYS = tuple(f.name for f in fields(FollowTargetParams) if f.init and f.name not in
                     ("width", "height"))

#: Defaults of the application's sections (a key absent here is unknown).
DEFAULTS = {
    "sim": {"duration": 20.0, "physics_dt": 1.0 / 240.0, "actuation_delay": None},
    "camera": {
        "resolution": "160x120",
        "fps": 30.0,
        "hfov": 1.047,
        "mount_height": None,  # None: the robot model's camera mount
        "mount_forward": None,
        "tilt": None,
        "noise_std": 0.0,
    },
    "color": {"initial": "red", "changes": []},
}


class ScenarioError(UsageError):
    """A scenario that cannot be loaded: unknown name, malformed file, bad value or key."""


def parse_resolution(text):
    """``"160x120"`` (or ``[160, 120]``) → ``(160, 120)``; ``ScenarioError`` when malformed."""
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
    if not (isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0):
        raise ScenarioError(
            f"resolution must look like WIDTHxHEIGHT, e.g. 160x120, 320x240 or 640x480; "
            f"got {text!r}"
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

    @property
    def frame_period(self):
        return 1.0 / self.fps


@dataclass(frozen=True)
class SimConfig:
    duration: float
    physics_dt: float
    actuation_delay: float


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

    def color_at(self, t):
        """The colour select in force at simulated time ``t``."""
        color = self.color_initial
        for at, c in self.color_changes:
            if at <= t + 1e-12:
                color = c
        return color

    def with_overrides(self, overrides):
        """A new scenario: this one's data with more ``KEY=VALUE`` overrides applied."""
        data = copy.deepcopy(self.data)
        _apply_overrides(data, overrides)
        return _build(data, self.source, tuple(self.overrides) + tuple(overrides))


# Loading ------------------------------------------------------------------------------------


def _scenario_dir():
    return resources.files("fpga_robotics") / "scenarios"


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
    looks_like_path = text.endswith(".toml") or "/" in text or "\\" in text
    if looks_like_path or Path(text).is_file():
        path = Path(text)
        if not path.is_file():
            raise ScenarioError(f"scenario file {text!r} does not exist")
        return path
    shipped = shipped_scenarios()
    if text in shipped:
        return Path(shipped[text][0])
    close = difflib.get_close_matches(text, shipped, n=3)
    hint = f" (did you mean {', '.join(close)}?)" if close else ""
    raise ScenarioError(
        f"unknown scenario {text!r}{hint}; shipped scenarios: {', '.join(shipped)} "
        f"(or give the path of a .toml file)"
    )


def load_scenario(name_or_path, overrides=()):
    """Load a shipped scenario by name, or a TOML file by path, and apply overrides.

    Parameters
    ----------
    name_or_path : str or Path
        A shipped scenario's name (``follow_person``) or a ``.toml`` path.
    overrides : list of str
        ``"dotted.key=value"`` items; the value is parsed as TOML (bare words are strings).

    Raises
    ------
    ScenarioError
        With one line that says what is wrong (unknown name, malformed TOML with its line,
        unknown key with close matches, invalid value).
    """
    path = _resolve(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{path}: malformed TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"cannot read scenario file {path}: {exc}") from None
    data.setdefault("name", path.stem)
    _check_known_keys(data, path)
    _fill_defaults(data)
    overrides = tuple(overrides or ())
    _apply_overrides(data, overrides)
    return _build(data, str(path), overrides)


def _check_known_keys(data, path):
    known = set(_TOP_KEYS) | set(WORLD_SECTIONS) | set(DEFAULTS) | {"design", "checks"}
    for key in data:
        if key not in known:
            raise ScenarioError(f"{path}: unknown top-level key {key!r}{_close(key, known)}")
    for section, allowed in (*((s, DEFAULTS[s]) for s in DEFAULTS), ("design", _DESIGN_KEYS),
                             ("checks", CHECKS)):
        value = data.get(section, {})
        if not isinstance(value, dict):
            raise ScenarioError(f"{path}: [{section}] must be a table")
        for key in value:
            if key not in allowed:
                if section == "design" and key in ("width", "height"):
                    raise ScenarioError(
                        f"{path}: design.{key} comes from camera.resolution; set that instead"
                    )
                raise ScenarioError(
                    f"{path}: unknown key {section}.{key}{_close(key, allowed, section)}"
                )


def _fill_defaults(data):
    for section, defaults in DEFAULTS.items():
        table = data.setdefault(section, {})
        for key, value in defaults.items():
            if key not in table and value is not None:
                table[key] = copy.deepcopy(value)
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
    out += [f"design.{k}" for k in _DESIGN_KEYS]
    out += [f"checks.{k}" for k in CHECKS]
    out += [f"{s}.{k}" for s, d in DEFAULTS.items() for k in d]
    return sorted(set(out))


def _apply_overrides(data, overrides):
    for item in overrides:
        if not isinstance(item, str) or "=" not in item:
            raise ScenarioError(f"--set needs KEY=VALUE (e.g. robot.mass=12), got {item!r}")
        key, text = item.split("=", 1)
        key = key.strip()
        value = _parse_value(text)
        _set_path(data, key, value)


def _set_path(data, key, value):
    parts = key.split(".")
    node = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        here = ".".join(parts[: i + 1])
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise ScenarioError(
                    f"unknown key {key!r}: {'.'.join(parts[:i])} is a list of {len(node)} "
                    f"item(s), index it with 0..{len(node) - 1}"
                )
            part = int(part)
            if last:
                node[part] = _coerce(node[part], value, key)
                return
            node = node[part]
            continue
        if not isinstance(node, dict):
            raise ScenarioError(f"unknown key {key!r}: {'.'.join(parts[:i])} is not a table")
        # Inside the world's sections any key may be set: the world validates the result
        # (with close matches) when the scenario is built.
        in_world = parts[0] in WORLD_SECTIONS
        if i == 0 and in_world and part not in data and parts[0] != "people":
            node[part] = {}
        optional = _optional_keys(parts[:i])
        if part not in node and part not in optional and not (in_world and last):
            if parts[:i] == ["design"] and part in ("width", "height"):
                raise ScenarioError(f"design.{part} comes from camera.resolution; "
                                    f"set camera.resolution=WxH (or --resolution) instead")
            raise ScenarioError(_unknown_key_message(data, key, here))
        if last:
            node[part] = _coerce(node.get(part), value, key)
            return
        node = node[part]


def _optional_keys(parents):
    """Keys that may be set although the file does not give them."""
    if len(parents) != 1:
        return ()
    section = parents[0]
    if section == "design":
        return _DESIGN_KEYS
    if section == "checks":
        return CHECKS
    return tuple(DEFAULTS.get(section, ()))


def _unknown_key_message(data, key, here):
    depth = key.count(".")
    paths = [p for p in _known_paths(data) if p.count(".") == depth]
    close = difflib.get_close_matches(key, paths, n=4, cutoff=0.6)
    if not close:
        # Suggest the siblings of the deepest known parent.
        parent = here.rsplit(".", 1)[0] if "." in here else ""
        close = [p for p in paths if parent and p.startswith(parent + ".")][:10]
    hint = f"; close matches: {', '.join(close)}" if close else ""
    return f"unknown scenario key {key!r}{hint}"


def _coerce(old, value, key):
    # An int where the scenario had a float is a float (``--set sim.duration=10``).
    if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value


# Validation ---------------------------------------------------------------------------------


def _number(data, section, key, *, lo=None, hi=None, lo_open=False, integer=False):
    value = data[section][key]
    name = f"{section}.{key}"
    ok_type = int if integer else (int, float)
    if isinstance(value, bool) or not isinstance(value, ok_type):
        kind = "an integer" if integer else "a number"
        raise ScenarioError(f"{name} must be {kind}, got {value!r}")
    if isinstance(value, float) and not math.isfinite(value):
        raise ScenarioError(f"{name} must be finite, got {value!r}")
    if lo is not None and (value <= lo if lo_open else value < lo):
        raise ScenarioError(f"{name} must be {'>' if lo_open else '>='} {lo}, got {value!r}")
    if hi is not None and value > hi:
        raise ScenarioError(f"{name} must be <= {hi}, got {value!r}")
    return value


def _optional(data, section, key, **limits):
    if data[section].get(key) is None:
        return None
    return float(_number(data, section, key, **limits))


def _color(value, where):
    if not isinstance(value, str) or value.lower() not in COLOR_SELECT:
        raise ScenarioError(f"{where} must be one of {', '.join(COLOR_SELECT)}; got {value!r}")
    return value.lower()


def _check_world(world):
    """Validate the world's sections now, so that a bad value is reported at load time."""
    from .sim.world import World, WorldConfigError

    try:
        # Building it also finds placement errors (a robot starting inside a person).
        World.from_config(copy.deepcopy(world), 0)
    except WorldConfigError as exc:
        raise ScenarioError(str(exc)) from None


def _build(data, source, overrides):
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise ScenarioError("name must be a non-empty string")
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ScenarioError(f"seed must be an integer >= 0, got {seed!r}")
    for section in WORLD_SECTIONS:
        if section in data and not isinstance(data[section], (dict, list)):
            raise ScenarioError(f"[{section}] must be a table")

    width, height = parse_resolution(data["camera"]["resolution"])
    camera = CameraConfig(
        width=width,
        height=height,
        fps=float(_number(data, "camera", "fps", lo=0, lo_open=True, hi=1000)),
        hfov=float(_number(data, "camera", "hfov", lo=0, lo_open=True, hi=math.pi - 1e-3)),
        mount_height=_optional(data, "camera", "mount_height", lo=0, lo_open=True),
        mount_forward=_optional(data, "camera", "mount_forward"),
        tilt=_optional(data, "camera", "tilt", lo=-math.pi / 2, hi=math.pi / 2),
        noise_std=float(_number(data, "camera", "noise_std", lo=0)),
    )
    duration = float(_number(data, "sim", "duration", lo=0, lo_open=True))
    dt = float(_number(data, "sim", "physics_dt", lo=0, lo_open=True, hi=camera.frame_period))
    if "actuation_delay" in data["sim"]:
        delay = float(_number(data, "sim", "actuation_delay", lo=0, hi=10.0))
    else:
        delay = camera.frame_period
    sim = SimConfig(duration=duration, physics_dt=dt, actuation_delay=delay)

    color = data["color"]
    initial = _color(color["initial"], "color.initial")
    changes = color["changes"]
    if not isinstance(changes, list):
        raise ScenarioError("color.changes must be a list of {at = seconds, color = \"...\"}")
    parsed = []
    for i, change in enumerate(changes):
        where = f"color.changes.{i}"
        if not isinstance(change, dict) or set(change) != {"at", "color"}:
            raise ScenarioError(f"{where} must be {{at = seconds, color = \"name\"}}, got "
                                f"{change!r}")
        at = change["at"]
        if isinstance(at, bool) or not isinstance(at, (int, float)) or at < 0:
            raise ScenarioError(f"{where}.at must be a time >= 0 in seconds, got {at!r}")
        parsed.append((float(at), _color(change["color"], f"{where}.color")))
    if [a for a, _ in parsed] != sorted(a for a, _ in parsed):
        raise ScenarioError("color.changes must be in time order")

    try:
        params = FollowTargetParams(width=width, height=height, **data["design"])
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"invalid design parameters (with resolution {width}x{height}): "
                            f"{exc}") from None

    checks = dict(data["checks"])
    for key, limit in checks.items():
        kind = CHECKS[key][0]
        if kind is bool:
            ok = isinstance(limit, bool)
        else:
            ok = not isinstance(limit, bool) and isinstance(limit, (int, float)) and limit >= 0
        if not ok:
            raise ScenarioError(
                f"checks.{key} must be {'true or false' if kind is bool else 'a number >= 0'}, "
                f"got {limit!r}"
            )

    world = {s: copy.deepcopy(data[s]) for s in WORLD_SECTIONS if s in data}
    _check_world(world)
    return Scenario(
        name=name,
        description=str(data.get("description", "")),
        source=source,
        seed=seed,
        data=data,
        world=world,
        camera=camera,
        sim=sim,
        color_initial=initial,
        color_changes=tuple(parsed),
        params=params,
        checks=checks,
        overrides=tuple(overrides),
    )
