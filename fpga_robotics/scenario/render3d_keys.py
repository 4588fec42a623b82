"""The scenario's ``[camera]`` keys that choose and tune the renderer (docs/render3d.md).

``camera.renderer`` is ``"raster"`` (the default, ``sim.camera``) or ``"mujoco"``
(``sim.render3d``); the other keys only matter to the 3D renderer: ``shadows``,
``shadow_size``, ``textures``, ``floor``, ``shine`` and ``lamps`` (an array of spot lamps,
``{pos = [x, y, z], aim = [x, y, z], color = [r, g, b], cutoff_deg = 45, shadows = true}``).
"""

import math

from fpga_robotics.scenario.errors import ScenarioError
from fpga_robotics.sim.camera.render3d.options import FLOORS, Lamp, Render3DOptions

__all__ = ["RENDERERS", "RENDER_DEFAULTS", "parse_render_keys"]

#: The renderers ``camera.renderer`` chooses from.
RENDERERS = ("raster", "mujoco")

#: Defaults of the renderer keys of ``[camera]``.
RENDER_DEFAULTS = {
    "renderer": "raster",
    "shadows": True,
    "shadow_size": 256,
    "textures": True,
    "floor": "planks",
    "shine": 0.0,
    "lamps": [],
}
_LAMP_KEYS = ("pos", "aim", "color", "cutoff_deg", "shadows")


def _number(value, name, lo, hi):
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if not (ok and math.isfinite(value) and lo <= value <= hi):
        raise ScenarioError(f"{name} must be a number in {lo:g}..{hi:g}, got {value!r}")
    return float(value)


def _vector(value, name, lo, hi):
    if not (isinstance(value, list) and len(value) == 3):
        raise ScenarioError(f"{name} must be an array of three numbers, got {value!r}")
    return tuple(_number(v, f"{name}[{i}]", lo, hi) for i, v in enumerate(value))


def _boolean(value, name):
    if not isinstance(value, bool):
        raise ScenarioError(f"{name} must be true or false, got {value!r}")
    return value


def _lamp(item, i):
    where = f"camera.lamps[{i}]"
    if not isinstance(item, dict):
        raise ScenarioError(
            f"{where} must be a table {{pos = [x, y, z], aim = [x, y, z], ...}}, got {item!r}"
        )
    unknown = [k for k in item if k not in _LAMP_KEYS]
    if unknown:
        raise ScenarioError(
            f"unknown key {where}.{unknown[0]}; known keys: {', '.join(_LAMP_KEYS)}"
        )
    for key in ("pos", "aim"):
        if key not in item:
            raise ScenarioError(f"{where}.{key} is required: a point [x, y, z] in m")
    pos = _vector(item["pos"], f"{where}.pos", -100, 100)
    aim = _vector(item["aim"], f"{where}.aim", -100, 100)
    if pos == aim:
        raise ScenarioError(
            f"{where}.aim must differ from its pos (the lamp shines from pos to aim)"
        )
    return Lamp(
        pos=pos,
        aim=aim,
        color=_vector(item.get("color", [0.5, 0.5, 0.5]), f"{where}.color", 0, 10),
        cutoff_deg=_number(item.get("cutoff_deg", 45.0), f"{where}.cutoff_deg", 1, 90),
        shadows=_boolean(item.get("shadows", True), f"{where}.shadows"),
    )


def parse_render_keys(cam, seed):
    """``(renderer, Render3DOptions)`` from the ``[camera]`` table ``cam`` (defaults filled);
    raises a ``ScenarioError`` naming the key."""
    renderer = cam["renderer"]
    if renderer not in RENDERERS:
        raise ScenarioError(
            f"camera.renderer must be one of {', '.join(map(repr, RENDERERS))}, got {renderer!r}"
        )
    size = cam["shadow_size"]
    if isinstance(size, bool) or not isinstance(size, int) or not 64 <= size <= 8192:
        raise ScenarioError(
            f"camera.shadow_size must be an integer in 64..8192 (pixels of a "
            f"light's shadow map), got {size!r}"
        )
    floor = cam["floor"]
    if floor not in FLOORS:
        raise ScenarioError(
            f"camera.floor must be one of {', '.join(map(repr, FLOORS))}, got {floor!r}"
        )
    lamps = cam["lamps"]
    if not isinstance(lamps, list):
        raise ScenarioError(
            f"camera.lamps must be an array of tables ([[camera.lamps]]), got {lamps!r}"
        )
    options = Render3DOptions(
        shadows=_boolean(cam["shadows"], "camera.shadows"),
        shadow_size=size,
        textures=_boolean(cam["textures"], "camera.textures"),
        floor=floor,
        shine=_number(cam["shine"], "camera.shine", 0, 1),
        lamps=tuple(_lamp(item, i) for i, item in enumerate(lamps)),
        seed=seed,
    )
    return renderer, options
