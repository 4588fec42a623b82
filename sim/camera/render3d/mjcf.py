"""The MJCF model of a scene: the room, its furniture, the people's bodies, lights, camera.

Built once per scene layout (walls and the number of people); every frame then only moves
mocap bodies (the camera, each person's root) and sets the people's joint angles. Nothing is
simulated: MuJoCo only computes where the parts are and draws them.

Surfaces come from ``Scene.walls``, grouped by what they belong to (``Wall.kind`` and
``Wall.part``): the room's walls become slabs outside the room, a box's four faces one solid
box, a divider's two faces one board. The ceiling is drawn as an unlit backdrop (the
skybox) rather than a solid, so that it does not block the directional light: the scene's
light shines into the room as through a glass roof and the room's walls cast shadows.
"""

import math
from dataclasses import dataclass

import numpy as np

from .body import JOINTS, REFERENCE_HEIGHT, REFERENCE_RADIUS, body_colors, person_height
from .floor_patches import patch_assets_and_geoms
from .textures import texture_rgb

__all__ = ["ModelSpec", "build_model_xml"]

#: Thickness of the room's wall slabs and of lone walls, m.
SLAB = 0.05
#: Texture size and the metres one texture covers, per kind.
_TEXTURES = {
    "paint": (256, 2.0),
    "planks": (512, 0.9),
    "tiles": (256, 1.6),
    "grain": (256, 1.0),
    "plain": (8, 1.0),
}


@dataclass
class ModelSpec:
    """What ``build_model_xml`` made besides the XML: texture pixels by texture name, and
    per person the names of its joints (``JOINTS`` order) and its root mocap body."""

    xml: str
    textures: dict
    people: list  # of (root body name, {joint: name})
    n_lamps: int


def _f(values):
    return " ".join(f"{v:.6g}" for v in values)


class _Materials:
    """Materials keyed by (texture kind, colour, specular), each with its own texture."""

    def __init__(self, options):
        self.options = options
        self.assets = []
        self.textures = {}
        self._names = {}

    def get(self, kind, color, specular=0.0, flat=False):
        """A material of texture ``kind``; ``flat``: for the floor plane (a 2D texture),
        else for boxes (a cube texture: the same pattern on every face)."""
        if not self.options.textures:
            kind = "plain"
        key = (kind, tuple(round(c, 6) for c in color), round(specular, 6), flat)
        if key in self._names:
            return self._names[key]
        i = len(self._names)
        size, metres = _TEXTURES[kind]
        tex, mat = f"tex{i}", f"mat{i}"
        rgb = texture_rgb(kind, color, size, self.options.seed + i)
        self.textures[tex] = rgb if flat else np.concatenate([rgb] * 6)
        repeat = 1.0 / metres
        self.assets.append(
            f'<texture name="{tex}" type="{"2d" if flat else "cube"}" builtin="flat" '
            f'width="{size}" height="{size}" rgb1="1 1 1"/>'
        )
        self.assets.append(
            f'<material name="{mat}" texture="{tex}" texuniform="{"true" if flat else "false"}" '
            f'texrepeat="{repeat:.6g} {repeat:.6g}" specular="{specular:.6g}" '
            f'shininess="0.3" reflectance="0"/>'
        )
        self._names[key] = mat
        return mat


def _group_walls(walls):
    groups = {}
    for i, w in enumerate(walls):
        key = (w.kind, w.part) if w.kind in ("room", "box", "divider") else ("", i)
        groups.setdefault(key, []).append(w)
    return groups


def _slab(w, thickness, offset):
    """A box geom for wall ``w``: ``thickness`` across, its centre line moved ``offset`` m
    along the wall's left normal."""
    ex, ey = w.x1 - w.x0, w.y1 - w.y0
    length = math.hypot(ex, ey)
    nx, ny = -ey / length, ex / length
    cx = (w.x0 + w.x1) / 2 + offset * nx
    cy = (w.y0 + w.y1) / 2 + offset * ny
    angle = math.atan2(ey, ex)
    return (
        f'pos="{_f((cx, cy, w.height / 2))}" euler="0 0 {angle:.6g}" '
        f'size="{_f((length / 2, thickness / 2, w.height / 2))}"'
    )


def _static_geoms(scene, mats):
    out = []
    groups = _group_walls(scene.walls)
    room = [w for (kind, _), ws in groups.items() if kind == "room" for w in ws]
    if room:
        cx = sum(w.x0 for w in room) / len(room)
        cy = sum(w.y0 for w in room) / len(room)
    for (kind, part), ws in groups.items():
        if kind == "room":
            for w in ws:
                # The slab lies outside the room: away from the room's centre.
                ex, ey = w.x1 - w.x0, w.y1 - w.y0
                left = -ey * (cx - w.x0) + ex * (cy - w.y0) > 0
                mat = mats.get("paint", w.color)
                out.append(
                    f'<geom type="box" {_slab(w, SLAB, -SLAB / 2 if left else SLAB / 2)} '
                    f'material="{mat}"/>'
                )
        elif kind == "box" and len(ws) == 4:
            w0, w1 = ws[0], ws[1]
            length = math.hypot(w0.x1 - w0.x0, w0.y1 - w0.y0)
            width = math.hypot(w1.x1 - w1.x0, w1.y1 - w1.y0)
            cx_ = sum(w.x0 for w in ws) / 4
            cy_ = sum(w.y0 for w in ws) / 4
            angle = math.atan2(w0.y1 - w0.y0, w0.x1 - w0.x0)
            mat = mats.get("paint", w0.color)
            out.append(
                f'<geom type="box" pos="{_f((cx_, cy_, w0.height / 2))}" '
                f'euler="0 0 {angle:.6g}" '
                f'size="{_f((length / 2, width / 2, w0.height / 2))}" material="{mat}"/>'
            )
        elif kind == "divider" and len(ws) == 2:
            a, b = ws
            length = math.hypot(a.x1 - a.x0, a.y1 - a.y0)
            thick = abs((b.x0 - a.x0) * -(a.y1 - a.y0) + (b.y0 - a.y0) * (a.x1 - a.x0)) / length
            cx_ = (a.x0 + a.x1 + b.x0 + b.x1) / 4
            cy_ = (a.y0 + a.y1 + b.y0 + b.y1) / 4
            angle = math.atan2(a.y1 - a.y0, a.x1 - a.x0)
            mat = mats.get("grain", a.color, mats.options.shine * 0.6)
            out.append(
                f'<geom type="box" pos="{_f((cx_, cy_, a.height / 2))}" '
                f'euler="0 0 {angle:.6g}" '
                f'size="{_f((length / 2, max(thick, 0.005) / 2, a.height / 2))}" '
                f'material="{mat}"/>'
            )
        else:
            for w in ws:
                mat = mats.get("plain", w.color)
                out.append(f'<geom type="box" {_slab(w, 0.02, 0.0)} material="{mat}"/>')
    return out


def _person(i, cyl, mats, shine):
    """A person's body: a mocap root at the feet, facing +x, with hinged limbs."""
    h = person_height(cyl.bands)
    s = h / REFERENCE_HEIGHT  # vertical scale
    k = cyl.radius / REFERENCE_RADIUS  # horizontal scale
    colors = body_colors(cyl.bands, h)
    shirt = mats.get("plain", colors.shirt, shine)
    trousers = mats.get("plain", colors.trousers, shine * 0.5)
    skin = mats.get("plain", colors.skin, 0.1)
    shoes = mats.get("plain", colors.shoes, 0.3)
    hair = mats.get("plain", colors.hair, 0.1)
    name = f"person{i}"
    joints = {j: f"{name}_{j}" for j in JOINTS}
    arm_r, leg_r = 0.042 * k, 0.075 * k
    sh_y = 0.158 * k  # shoulder joint, from the middle: the arms reach out to the radius
    hip_y, hip_z = 0.082 * k, 0.86 * s
    torso = (0.13 * k, 0.12 * k, (1.40 - 0.85) / 2 * s)
    upper_arm, forearm = 0.29 * s, 0.27 * s
    thigh, shin = 0.40 * s, 0.40 * s
    lines = [
        f'<body name="{name}" mocap="true" pos="{_f((cyl.x, cyl.y, 0))}">',
        (
            f'<geom type="box" pos="{_f((0, 0, (0.85 + 1.40) / 2 * s))}" size="{_f(torso)}" '
            f'material="{shirt}"/>'
        ),
        # Hips in the trousers' colour: they hide the torso's underside from a camera
        # below it, as the raster's bands do.
        (
            f'<geom type="box" pos="{_f((0, 0, 0.785 * s))}" '
            f'size="{_f((0.128 * k, 0.118 * k, 0.075 * s))}" material="{trousers}"/>'
        ),
        # Shoulders: a bar across the top of the torso.
        (
            f'<geom type="capsule" fromto="{_f((0, -0.115 * k, 1.40 * s, 0, 0.115 * k, 1.40 * s))}"'
            f' size="{0.05 * k:.6g}" material="{shirt}"/>'
        ),
        (
            f'<geom type="cylinder" pos="{_f((0, 0, 1.47 * s))}" '
            f'size="{_f((0.045 * k, 0.05 * s))}" material="{skin}"/>'
        ),
        (
            f'<geom type="ellipsoid" pos="{_f((0, 0, 1.625 * s))}" '
            f'size="{_f((0.1 * k, 0.085 * k, 0.115 * s))}" material="{skin}"/>'
        ),
        (
            f'<geom type="ellipsoid" pos="{_f((-0.015 * k, 0, 1.68 * s))}" '
            f'size="{_f((0.1 * k, 0.09 * k, 0.075 * s))}" material="{hair}"/>'
        ),
    ]
    for side, y in (("l", sh_y), ("r", -sh_y)):
        lines += [
            f'<body pos="{_f((0, y, 1.40 * s))}">',
            f'<joint name="{joints["shoulder_" + side]}" type="hinge" axis="0 -1 0"/>',
            (
                f'<geom type="capsule" fromto="{_f((0, 0, 0, 0, 0, -upper_arm))}" '
                f'size="{arm_r:.6g}" material="{shirt}"/>'
            ),
            f'<body pos="{_f((0, 0, -upper_arm))}">',
            f'<joint name="{joints["elbow_" + side]}" type="hinge" axis="0 -1 0"/>',
            (
                f'<geom type="capsule" fromto="{_f((0, 0, 0, 0, 0, -forearm))}" '
                f'size="{arm_r * 0.9:.6g}" material="{shirt}"/>'
            ),
            (
                f'<geom type="sphere" pos="{_f((0, 0, -forearm - 0.05 * s))}" '
                f'size="{0.045 * k:.6g}" material="{skin}"/>'
            ),
            "</body></body>",
        ]
    for side, y in (("l", hip_y), ("r", -hip_y)):
        lines += [
            f'<body pos="{_f((0, y, hip_z))}">',
            f'<joint name="{joints["hip_" + side]}" type="hinge" axis="0 -1 0"/>',
            (
                f'<geom type="capsule" fromto="{_f((0, 0, 0, 0, 0, -thigh))}" '
                f'size="{leg_r:.6g}" material="{trousers}"/>'
            ),
            f'<body pos="{_f((0, 0, -thigh))}">',
            # A knee bends the shin backwards.
            f'<joint name="{joints["knee_" + side]}" type="hinge" axis="0 1 0"/>',
            (
                f'<geom type="capsule" fromto="{_f((0, 0, 0, 0, 0, -shin))}" '
                f'size="{leg_r * 0.85:.6g}" material="{trousers}"/>'
            ),
            (
                f'<geom type="box" pos="{_f((0.04 * k, 0, -shin - 0.01 * s))}" '
                f'size="{_f((0.12 * k, 0.05 * k, 0.045 * s))}" material="{shoes}"/>'
            ),
            "</body></body>",
        ]
    lines.append("</body>")
    return name, joints, lines


def build_model_xml(scene, options, width, height, fovy_deg):
    """The MJCF of ``scene`` for a ``width`` x ``height`` camera of vertical field of view
    ``fovy_deg``; a ``ModelSpec``."""
    mats = _Materials(options)
    floor_kind = options.floor
    room = [w for w in scene.walls if w.kind == "room"]
    xs = [c for w in (room or scene.walls) for c in (w.x0, w.x1)] or [-5.0, 5.0]
    ys = [c for w in (room or scene.walls) for c in (w.y0, w.y1)] or [-5.0, 5.0]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    half = max(x1 - x0, y1 - y0, 1.0) / 2 + 0.5
    ceiling = scene.ceiling_height
    body = []
    floor_mat = mats.get(floor_kind, scene.floor_color, flat=True)
    body.append(
        f'<geom type="plane" pos="{_f((cx, cy, 0))}" '
        f'size="{_f((half + SLAB, half + SLAB, 0.1))}" material="{floor_mat}"/>'
    )
    body += _static_geoms(scene, mats)
    patch_assets, patch_geoms = patch_assets_and_geoms(scene)  # terrain drawn on the floor
    body += patch_geoms
    people = []
    for i, cyl in enumerate(scene.cylinders):
        name, joints, lines = _person(i, cyl, mats, options.shine)
        people.append((name, joints))
        body += lines
    body.append(f'<body name="eye" mocap="true"><camera name="eye" fovy="{fovy_deg:.8g}"/></body>')
    # Light 0: the scene's directional light, above the room (its shadow map covers it).
    # Its strengths are set every frame from Scene.lighting.
    shadow = "true" if options.shadows else "false"
    lights = [
        (
            f'<light name="sun" directional="true" pos="{_f((cx, cy, ceiling + 4 * half))}" '
            f'dir="1 0.5 -1" castshadow="{shadow}" ambient="0 0 0" specular="0.3 0.3 0.3"/>'
        )
    ]
    for j, lamp in enumerate(options.lamps):
        d = [a - p for a, p in zip(lamp.aim, lamp.pos)]
        cast = "true" if options.shadows and lamp.shadows else "false"
        lights.append(
            f'<light name="lamp{j}" directional="false" pos="{_f(lamp.pos)}" dir="{_f(d)}" '
            f'cutoff="{lamp.cutoff_deg:.6g}" exponent="2" diffuse="{_f(lamp.color)}" '
            f'specular="{_f([0.5 * c for c in lamp.color])}" ambient="0 0 0" '
            f'attenuation="1 0 0" castshadow="{cast}"/>'
        )
    xml = "\n".join(
        [
            '<mujoco model="scene">',
            '<compiler angle="radian"/>',
            "<visual>",
            f'<global offwidth="{max(width, 1)}" offheight="{max(height, 1)}"/>',
            f'<quality shadowsize="{options.shadow_size}" offsamples="0"/>',
            '<headlight active="1" ambient="0 0 0" diffuse="0 0 0" specular="0 0 0"/>',
            (
                f'<map znear="0.005" zfar="{8 * half + 2 * ceiling:.6g}" shadowclip="1.2" '
                f'shadowscale="0.6" haze="0"/>'
            ),
            '<rgba haze="0 0 0 1"/>',
            "</visual>",
            f'<statistic center="{_f((cx, cy, ceiling / 2))}" extent="{half * 1.2:.6g}"/>',
            "<asset>",
            (
                '<texture name="ceiling" type="skybox" builtin="flat" width="8" height="8" '
                'rgb1="1 1 1" rgb2="1 1 1"/>'
            ),
            *mats.assets,
            *patch_assets,
            "</asset>",
            "<worldbody>",
            *lights,
            *body,
            "</worldbody>",
            "</mujoco>",
        ]
    )
    return ModelSpec(xml, mats.textures, people, len(options.lamps))
