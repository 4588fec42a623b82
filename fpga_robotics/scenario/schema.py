"""The keys of the application's sections (``[sim]``, ``[camera]`` with ``[camera.ov7670]``
and ``[[camera.lamps]]``, ``[color]``, ``[design]``, ``[checks]``) and the top-level keys,
each declared once: type, default, valid range, unit and meaning (docs/scenarios.md).

The world's sections have theirs in ``sim.world.keys``; both are pydantic models of
``sim.world.schema``. Relations between keys (the physics step at most a frame period, the
camera below the ceiling, the size of a run) are checked by ``fpga_robotics.scenario.load``.
Sections whose keys come from a registry are built from it: ``[camera.ov7670]`` from the sensor
model's ``PARAMS``, ``[design]`` from ``FollowTargetParams``, ``[checks]`` from ``CHECKS``.
"""

import difflib
import math
from dataclasses import fields
from functools import cache
from typing import Annotated

from pydantic import BeforeValidator, Field, create_model, model_validator
from pydantic_core import PydanticCustomError

from fpga_robotics.checks.summary import CHECKS
from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.hw.params import (
    CHOICES,
    DEFAULT_BASE_DPS,
    DEFAULT_PROXIMITY_THRESHOLDS,
    DEFAULT_STEER_DPS,
    FollowTargetParams,
)
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.sim.camera.render3d.options import FLOORS, MAX_LAMPS
from fpga_robotics.sim.camera.sensor import PARAMS as SENSOR_PARAMS
from fpga_robotics.sim.world.keys import MAX_TIME
from fpga_robotics.sim.world.schema import (
    Flag,
    Integer,
    KeyModel,
    Number,
    Text,
    check_of,
    checked,
    fail,
)

__all__ = [
    "MAX_SEED",
    "RENDERERS",
    "TIMINGS",
    "CameraKeys",
    "ColorKeys",
    "LampKeys",
    "ScenarioKeys",
    "SimKeys",
    "TopKeys",
    "checks_keys",
    "defaults_of",
    "design_keys",
    "ov7670_keys",
]

#: Seeds are integers 0..2**63-1.
MAX_SEED = 2**63 - 1
#: ``sim.timing`` values.
TIMINGS = ("auto", "compressed", "real_clock")
#: The renderers ``camera.renderer`` chooses from.
RENDERERS = ("raster", "mujoco")


def _scenario_number(**bounds):
    return Number(style="scenario", **bounds)


class ScenarioKeys(KeyModel):
    """A table of the application's sections: an unknown key is named with its section and
    the closest known keys."""

    @classmethod
    def unknown_key(cls, path, key):
        section = path.rpartition(".")[0]
        close = difflib.get_close_matches(str(key), cls.key_names(), n=3, cutoff=0.5)
        hint = f" (did you mean {', '.join(f'{section}.{c}' for c in close)}?)" if close else ""
        return f"unknown key {path}{hint}"


class TopKeys(ScenarioKeys):
    """The keys outside any section."""

    #: A file name (the loader checks it and defaults it to the file's name).
    name: Annotated[object, Field(description="the run's recording is runs/<name>.rrd")] = None
    description: Text(style="scenario", doc="one line, shown by the scenario list") = ""
    seed: Integer(ge=0, le=MAX_SEED, doc="the default seed of a run (`--seed`)") = 0


class SimKeys(ScenarioKeys):
    duration: _scenario_number(
        gt=0, le=MAX_TIME, unit="s", note=" (one day)", doc="simulated time of a run"
    ) = 20.0
    physics_dt: _scenario_number(
        ge=1e-5, unit="s", doc="physics step; at most one camera frame period (`1 / camera.fps`)"
    ) = 1.0 / 240.0
    actuation_delay: _scenario_number(
        ge=0,
        le=10,
        unit="s",
        doc="a command's way to the wheels; unset: one frame period (compressed timing) or "
        "0.001 s, one SPI message (real-clock timing)",
    ) = None
    timing: Text(
        choices=TIMINGS,
        style="scenario",
        doc='"auto": "compressed" for a camera-only design (docs/your_design.md), else '
        '"real_clock" (docs/running.md)',
    ) = "auto"
    clock_hz: _scenario_number(
        ge=1e3,
        le=1e9,
        unit="Hz",
        doc="the design's clock in real-clock timing; unset: 5e7 (50 MHz)",
    ) = None


def _vector3(lo, hi):
    def check(value):
        if not (isinstance(value, list) and len(value) == 3):
            fail(f"must be an array of three numbers, got {value!r}")
        item = check_of(Number(ge=lo, le=hi, style="span"))
        return tuple(checked(item, v, f"[{i}]") for i, v in enumerate(value))

    return Annotated[tuple[float, float, float], BeforeValidator(check)]


class LampKeys(ScenarioKeys):
    """A spot lamp of the 3D renderer (docs/render3d.md)."""

    pos: Annotated[_vector3(-100, 100), Field(description="a point [x, y, z] in m")]
    aim: Annotated[_vector3(-100, 100), Field(description="a point [x, y, z] in m")]
    color: Annotated[_vector3(0, 10), Field(description="its light, r, g, b")] = (0.5, 0.5, 0.5)
    cutoff_deg: Number(ge=1, le=90, style="span", doc="the cone's half angle, deg") = 45.0
    shadows: Flag(style="scenario", doc="casts shadows (when camera.shadows)") = True

    @classmethod
    def unknown_key(cls, path, key):
        return f"unknown key {path}; known keys: {', '.join(cls.key_names())}"

    @model_validator(mode="after")
    def _apart(self):
        if self.pos == self.aim:
            raise ValueError("aim must differ from its pos (the lamp shines from pos to aim)")
        return self


def _lamps(value):
    if not isinstance(value, list):
        fail(f"must be an array of tables ([[camera.lamps]]), got {value!r}")
    if len(value) > MAX_LAMPS:
        fail(
            f"must hold at most {MAX_LAMPS} lamps (the 3D renderer draws 8 lights, two of them "
            f"the scenario's [lighting]), got {len(value)}"
        )
    for i, item in enumerate(value):
        if not isinstance(item, dict):
            fail(
                f"must be a table {{pos = [x, y, z], aim = [x, y, z], ...}}, got {item!r}",
                sub=f"[{i}]",
            )
    return value


def _ov7670_key(kind, limits, unit, doc):
    if kind == "bool":
        return Flag(style="scenario", doc=doc)
    if kind == "choice":
        return Text(choices=limits, style="scenario", doc=doc)
    if kind == "float":
        return _scenario_number(ge=limits[0], le=limits[1], unit=unit, doc=doc)
    if kind == "int":
        message = "must be an integer {lo}..{hi} ({unit}), got {value!r}"
        return Integer(ge=limits[0], le=limits[1], unit=unit, doc=doc, message=message)
    lo, hi = limits

    def pair(value):
        ok = isinstance(value, list) and len(value) == 2
        ok = ok and all(isinstance(v, int) and not isinstance(v, bool) for v in value)
        if not (ok and all(lo <= v <= hi for v in value) and value[0] < value[1]):
            fail(
                f"must be [low, high], integers {lo}..{hi} with low < high ({unit}), got {value!r}"
            )
        return tuple(value)

    return Annotated[tuple[int, int], BeforeValidator(pair), Field(description=doc)]


@cache
def ov7670_keys():
    """``[camera.ov7670]``, built from the sensor model's ``PARAMS`` (its defaults, limits and
    sources)."""
    keys = {
        key: (_ov7670_key(kind, limits, unit, source), list(default) if kind == "pair" else default)
        for key, (default, kind, limits, unit, source) in SENSOR_PARAMS.items()
    }
    return create_model("OV7670Keys", __base__=ScenarioKeys, **keys)


class CameraKeys(ScenarioKeys):
    resolution: Annotated[
        object, Field(description='"WxH": width 16..4096, height 2..4096 (the design\'s limits)')
    ] = "160x120"
    fps: _scenario_number(ge=0.1, le=1000.0, unit="frames/s", doc="frame rate") = 30.0
    hfov: _scenario_number(
        ge=0.01,
        le=3.1,
        unit="rad",
        doc="horizontal field of view; at most what the aspect ratio allows with the tilt",
    ) = 1.047
    mount_height: _scenario_number(
        gt=0, unit="m", doc="above the floor, below the ceiling; unset: robot.camera_height"
    ) = None
    mount_forward: _scenario_number(
        ge=-2, le=2, unit="m", doc="ahead of the robot's centre; unset: robot.camera_forward"
    ) = None
    tilt: _scenario_number(
        ge=-math.pi / 2,
        le=math.pi / 2,
        unit="rad",
        doc="up positive, within the field-of-view limit; unset: robot.camera_tilt_deg",
    ) = None
    noise_std: _scenario_number(
        ge=0, le=64, unit="8-bit levels", doc="Gaussian noise on each pixel"
    ) = 0.0
    yaw_offset_deg: _scenario_number(
        ge=-45, le=45, unit="deg", doc="the mount knocked off its pose (positive: turned left)"
    ) = 0.0
    exposure_drift: _scenario_number(
        ge=0, le=2, unit="", doc="std of the log brightness gain's slow drift (10 s correlation)"
    ) = 0.0
    sensor: Text(
        choices=("plain", "ov7670"),
        style="scenario",
        doc='the sensor model after the renderer ("ov7670": [camera.ov7670], docs/camera.md)',
    ) = "plain"
    ov7670: Annotated[
        object, Field(description="the OV7670 model's parameters (docs/camera.md)")
    ] = None
    renderer: Text(
        choices=RENDERERS, style="scenario", doc='"mujoco": the 3D renderer (docs/render3d.md)'
    ) = "raster"
    shadows: Flag(style="scenario", doc="3D renderer: shadows") = True
    shadow_size: Integer(
        ge=64,
        le=8192,
        doc="3D renderer: pixels of a light's shadow map",
        message="must be an integer in {lo}..{hi} (pixels of a light's shadow map), got {value!r}",
    ) = 256
    textures: Flag(
        style="scenario", doc="3D renderer: textures on walls, floor and wood; false: flat colours"
    ) = True
    floor: Text(choices=FLOORS, style="scenario", doc="3D renderer: the floor's texture") = "planks"
    shine: Number(
        ge=0, le=1, style="span", doc="3D renderer: specular strength of clothes and wood"
    ) = 0.0
    lamps: Annotated[
        list[LampKeys],
        BeforeValidator(_lamps),
        Field(description="3D renderer: spot lamps ([[camera.lamps]])"),
    ] = ()


def _color(value):
    if not isinstance(value, str) or value.lower() not in COLOR_SELECT:
        fail(f"must be one of {', '.join(COLOR_SELECT)}; got {value!r}")
    return value.lower()


Color = Annotated[str, BeforeValidator(_color)]


def _changes(value):
    """``[{at = seconds, color = "..."}, ...]`` in time order."""
    if not isinstance(value, list):
        fail('must be a list of {at = seconds, color = "..."}')
    at = check_of(Number(ge=0, le=MAX_TIME))
    out = []
    for i, change in enumerate(value):
        if not isinstance(change, dict) or set(change) != {"at", "color"}:
            fail(f'must be {{at = seconds, color = "name"}}, got {change!r}', sub=f"[{i}]")
        try:
            t = at(change["at"])
        except PydanticCustomError:
            fail(f"must be a time in 0..{MAX_TIME:g} s, got {change['at']!r}", sub=f"[{i}].at")
        out.append((t, checked(_color, change["color"], f"[{i}].color")))
    if [t for t, _ in out] != sorted(t for t, _ in out):
        fail("must be in time order")
    return tuple(out)


class ColorKeys(ScenarioKeys):
    initial: Annotated[Color, Field(description="the colour the design selects at t = 0")] = "red"
    changes: Annotated[
        object,
        BeforeValidator(_changes),
        Field(description='[{at = s, color = "..."}, ...], in time order, at 0..86400 s'),
    ] = ()


def _design_key(name):
    if name in CHOICES:
        choices = CHOICES[name]

        def check(value):
            if not isinstance(value, str):
                fail(f"must be a string, one of {', '.join(choices)}; got {value!r}")
            return value  # FollowTargetParams checks the choice

        return Annotated[str, BeforeValidator(check)]
    if name in DESIGN_ARRAYS:
        n, what = DESIGN_ARRAYS[name]

        def check(value):
            ints = isinstance(value, list) and len(value) == n
            if not (ints and all(isinstance(v, int) and not isinstance(v, bool) for v in value)):
                fail(f"must be an array of {n} integers ({what}), got {value!r}")
            return value

        return Annotated[list, BeforeValidator(check)]

    def integer(value):
        if isinstance(value, bool) or not isinstance(value, int):
            fail(f"must be an integer, got {value!r}")
        return value  # its range: FollowTargetParams

    return Annotated[int, BeforeValidator(integer)]


#: Design parameters that are arrays: their length and what the values are.
DESIGN_ARRAYS = {
    "base_dps": (len(DEFAULT_BASE_DPS), "wheel DPS per proximity level 0..7"),
    "proximity_thresholds": (len(DEFAULT_PROXIMITY_THRESHOLDS), "pixel counts of levels 1..7"),
    "steer_dps": (len(DEFAULT_STEER_DPS), "DPS by LED distance 0..3 from the centre"),
}
#: ``design.top``, every built-in top's parameter tables, a foreign design's files: checked
#: by load.py (they name files and designs); ``design.preset``:
#: ``FollowTargetParams.published()`` first.
DESIGN_OTHER_KEYS = (
    "preset",
    "top",
    "variant",
    "params",
    *dict.fromkeys(key for top in TOPS.values() for key in top.tables),
    "verilog",
    "ports",
    "defines",
)


class _DesignBase(ScenarioKeys):
    @classmethod
    def unknown_key(cls, path, key):
        if key in ("width", "height"):
            return f"design.{key} comes from camera.resolution; set that instead"
        return super().unknown_key(path, key)


@cache
def design_keys():
    """``[design]``: every ``FollowTargetParams`` field but the resolution (the types here,
    the ranges and relations in ``FollowTargetParams``), and the keys that choose the design."""
    keys = {k: (object, None) for k in DESIGN_OTHER_KEYS}
    for f in fields(FollowTargetParams):
        if f.init and f.name not in ("width", "height"):
            keys[f.name] = (_design_key(f.name), None)
    return create_model("DesignKeys", __base__=_DesignBase, **keys)


def _check_key(kind, limits, meaning):
    lo, hi, unit = limits
    if kind is int:
        return Integer(ge=lo, le=hi, doc=meaning)
    return Number(ge=lo, le=hi, unit=unit, style="span", doc=meaning)


def checks_keys():
    """``[checks]``: one key per registered check (``CHECKS``; the registry may grow)."""
    return _checks_keys(tuple(CHECKS))


@cache
def _checks_keys(names):
    keys = {name: (_check_key(*CHECKS[name]), None) for name in names}
    return create_model("ChecksKeys", __base__=ScenarioKeys, **keys)


def defaults_of(model):
    """The model's defaults as plain TOML values (None: no default, the key stays out)."""
    out = {}
    for name, f in model.model_fields.items():
        value = f.default
        out[name] = list(value) if isinstance(value, tuple) else value
    return out
