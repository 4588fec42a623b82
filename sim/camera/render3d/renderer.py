"""MujocoRenderer: the camera's frame drawn by MuJoCo off-screen (OpenGL through EGL or
OSMesa), with textures, lights, shadows and people with bodies.

Same call as ``sim.camera.CameraRenderer``: ``render(scene, pose, noise_std, rng)`` returns
an RGB888 (height, width, 3) uint8 image, with the same pinhole (focal length
``(W/2) / tan(hfov/2)``, square pixels, optical axis through the image centre) and the same
light model for the scene's light: ``albedo * (ambient + intensity * max(0, -n.d))``, bright
light beyond 1 included (drawn scaled down and the frame multiplied back). The
model is built from the scene's layout once (``mjcf.build_model_xml``) and rebuilt only when
the walls or the people change; every frame then moves the camera and the people (mocap
bodies, the gait's joint angles from ``body.gait_angles``) and sets the light levels.
MuJoCo's physics is never stepped: the world's physics is pymunk's.
"""

import math
import os

import numpy as np

from fpga_robotics.hw.errors import UserError
from fpga_robotics.hw.validate import check_int

from ..raster import DEFAULT_HFOV, CameraRenderer, vertical_fov
from ..scene import CameraPose, Scene
from .body import gait_angles, person_height
from .mjcf import build_model_xml
from .options import Render3DOptions

__all__ = ["INSTALL_HINT", "MujocoRenderer", "Render3DUnavailable", "load_mujoco"]

INSTALL_HINT = (
    'install it with: pip install -e ".[realistic]" and, on Debian/Ubuntu, '
    "apt-get install libegl1 libgl1-mesa-dri"
)


class Render3DUnavailable(UserError, RuntimeError):
    """MuJoCo or an off-screen OpenGL context is missing; the message says how to install."""


def load_mujoco():
    """The ``mujoco`` module, imported for off-screen drawing; ``Render3DUnavailable`` when
    it is missing."""
    # MuJoCo picks its OpenGL platform when first imported: off-screen EGL unless the user
    # chose another (MUJOCO_GL=osmesa).
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco  # lazy: optional (realistic extra), after MUJOCO_GL is set
    except ImportError:
        raise Render3DUnavailable(f"the 3D renderer needs MuJoCo; {INSTALL_HINT}") from None
    # An unknown MUJOCO_GL raises RuntimeError; a missing GL library whatever its platform's
    # binding raises (PyOpenGL without libOSMesa: AttributeError).
    except Exception as exc:  # noqa: BLE001
        raise _no_context(exc) from None
    return mujoco


def _no_context(exc):
    return Render3DUnavailable(
        f"no off-screen OpenGL context for the 3D renderer (MUJOCO_GL="
        f"{os.environ.get('MUJOCO_GL')}: {exc}); {INSTALL_HINT}"
    )


def _quat_yaw(angle):
    return (math.cos(angle / 2), 0.0, 0.0, math.sin(angle / 2))


def _camera_quat(mujoco, heading, tilt):
    """MuJoCo's camera looks along its -z with +y up: columns right, up, -forward."""
    ch, sh, ct, st = math.cos(heading), math.sin(heading), math.cos(tilt), math.sin(tilt)
    forward = np.array([ch * ct, sh * ct, st])
    right = np.array([sh, -ch, 0.0])
    up = np.cross(right, forward)
    mat = np.column_stack([right, up, -forward])
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, mat.ravel())
    return quat


class MujocoRenderer:
    """3D renderer for one image size (``CameraRenderer``'s interface).

    Parameters
    ----------
    width, height : int
    hfov : float
        Horizontal field of view, rad.
    options : Render3DOptions
        Shadows, textures, lamps, shine (defaults: shadows on, textures on, no lamps).

    Raises
    ------
    Render3DUnavailable
        MuJoCo is not installed, or no off-screen OpenGL context can be made (at the first
        ``render``, when the context is made).
    """

    def __init__(self, width, height, hfov=DEFAULT_HFOV, options=None):
        check_int("width", width, 1)
        check_int("height", height, 1)
        self._mj = load_mujoco()
        # The raster renderer checks the geometry (field of view, tilt) and adds the noise.
        self._raster = CameraRenderer(width, height, hfov)
        self.width, self.height, self.hfov = int(width), int(height), float(hfov)
        self.focal = self._raster.focal
        self.options = options or Render3DOptions()
        self._fovy = math.degrees(vertical_fov(self.width, self.height, self.hfov))
        self._key = None
        self._renderer = None
        self._sky = None

    def __repr__(self):
        return (
            f"MujocoRenderer(width={self.width}, height={self.height}, hfov={self.hfov}, "
            f"options={self.options})"
        )

    def prepare(self):
        """Check now that an off-screen OpenGL context can be made (else
        ``Render3DUnavailable``), rather than at the first frame."""
        try:
            context = self._mj.GLContext(self.width, self.height)
            context.make_current()
            context.free()
        except Exception as exc:  # noqa: BLE001 (each GL platform raises its own types)
            raise _no_context(exc) from None

    def close(self):
        """Free the OpenGL context (also done when the renderer is garbage collected)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
            self._key = None

    # -- the model, rebuilt when the layout changes -------------------------------------------

    def _layout_key(self, scene):
        # Compared by value (a tuple compares its items by identity first: cheap per frame).
        return (
            scene.walls,
            tuple((c.bands, c.radius) for c in scene.cylinders),
            scene.floor_color,
            scene.ceiling_color,
            scene.ceiling_height,
            getattr(scene, "floor_patches", ()),
        )

    def _build(self, scene):
        mj = self._mj
        self.close()
        spec = build_model_xml(scene, self.options, self.width, self.height, self._fovy)
        model = mj.MjModel.from_xml_string(spec.xml)
        for name, rgb in spec.textures.items():
            tid = mj.mj_name2id(model, mj.mjtObj.mjOBJ_TEXTURE, name)
            adr = model.tex_adr[tid]
            model.tex_data[adr : adr + rgb.size] = rgb.ravel()
        self._sky_id = mj.mj_name2id(model, mj.mjtObj.mjOBJ_TEXTURE, "ceiling")
        self._centre = np.array(model.stat.center)
        self.model, self.data = model, mj.MjData(model)
        try:
            self._renderer = mj.Renderer(model, self.height, self.width)
        except Exception as exc:  # noqa: BLE001 (each GL platform raises its own types)
            raise _no_context(exc) from None
        self._eye = model.body("eye").mocapid[0]
        self._people = []
        for name, joints in spec.people:
            mocap = model.body(name).mocapid[0]
            qadr = [model.jnt_qposadr[model.joint(joints[j]).id] for j in joints]
            self._people.append((mocap, list(joints), qadr))
        self._sky = None
        # The lights' strengths as the model gives them, scaled down each frame (_set_lights).
        self._lamp_diffuse = model.light_diffuse[1:].copy()
        self._specular = model.light_specular.copy()
        self._key = self._layout_key(scene)

    # -- the frame -----------------------------------------------------------------------------

    def _set_lights(self, lighting):
        """Set the frame's light levels, divided by ``self._gain``, the most they can sum to
        (at least 1): OpenGL clips the summed light at 1 before it scales a surface's colour,
        so a brighter light is drawn dimmer and ``render`` multiplies the frame back."""
        m = self.model
        lamps = self._lamp_diffuse.sum(axis=0).max() if len(self._lamp_diffuse) else 0.0
        gain = max(1.0, lighting.ambient + lighting.intensity + lamps)
        self._gain = gain
        d = np.asarray(lighting.direction, dtype=float)
        d = d / np.linalg.norm(d)
        m.light_dir[0] = d
        # The shadow map's box is centred on the light's axis: through the room's centre.
        m.light_pos[0] = self._centre - 2.0 * m.stat.extent * d
        m.light_diffuse[0] = lighting.intensity / gain
        m.light_diffuse[1:] = self._lamp_diffuse / gain
        m.light_specular[:] = self._specular / gain
        # Ambient light comes from the headlight (diffuse 0): a light's own ambient term
        # would vanish in its shadows, leaving them black.
        m.vis.headlight.ambient = (lighting.ambient / gain,) * 3
        # The ceiling is lit by the ambient light only (the raster's ceiling).
        sky = (self._scene_ceiling * lighting.ambient).clip(0.0, 1.0) / gain
        if self._sky is None or not np.array_equal(sky, self._sky):
            adr = m.tex_adr[self._sky_id]
            n = m.tex_width[self._sky_id] * m.tex_height[self._sky_id] * 3
            m.tex_data[adr : adr + n] = np.tile(np.rint(sky * 255).astype(np.uint8), n // 3)
            if self._renderer is not None:
                self._mj.mjr_uploadTexture(m, self._renderer._mjr_context, self._sky_id)
            self._sky = sky

    def _place(self, scene, pose):
        d = self.data
        d.mocap_pos[self._eye] = (pose.x, pose.y, pose.height)
        d.mocap_quat[self._eye] = _camera_quat(self._mj, pose.heading, pose.tilt)
        for (mocap, joints, qadr), cyl in zip(self._people, scene.cylinders):
            d.mocap_pos[mocap] = (cyl.x, cyl.y, 0.0)
            d.mocap_quat[mocap] = _quat_yaw(cyl.facing)
            angles = gait_angles(cyl.walked, cyl.speed, person_height(cyl.bands))
            for j, a in zip(joints, qadr):
                d.qpos[a] = angles[j]
        self._mj.mj_kinematics(self.model, d)
        self._mj.mj_camlight(self.model, d)

    def render(self, scene, pose, noise_std=0.0, rng=None):
        """Render ``scene`` seen from ``pose``; (height, width, 3) uint8 RGB.

        ``noise_std`` (8-bit levels) adds Gaussian sensor noise drawn from ``rng``, as
        ``CameraRenderer.render`` does.
        """
        if not isinstance(scene, Scene):
            raise TypeError(
                f"scene must be a fpga_robotics.sim.camera.scene.Scene, not {type(scene)}"
            )
        if not isinstance(pose, CameraPose):
            raise TypeError(
                f"pose must be a fpga_robotics.sim.camera.scene.CameraPose, not {type(pose)}"
            )
        ceiling = float(scene.ceiling_height)
        if not 0.0 < pose.height < ceiling:
            raise ValueError(
                f"camera height {pose.height} m must be between the floor (0) and "
                f"the ceiling ({ceiling} m)"
            )
        if abs(pose.tilt) > self._raster.max_tilt:
            raise ValueError(
                f"camera tilt {pose.tilt:.4f} rad would look straight up or down; "
                f"keep |tilt| <= {self._raster.max_tilt:.4f} rad"
            )
        if self._key != self._layout_key(scene):
            self._scene_ceiling = np.asarray(scene.ceiling_color, dtype=float)
            self._build(scene)
        self._set_lights(scene.lighting)
        self._place(scene, pose)
        r = self._renderer
        r.update_scene(self.data, camera="eye")
        image = r.render()
        if self._gain > 1.0:  # the light drawn divided by the gain (_set_lights)
            image = np.minimum(np.rint(image * self._gain), 255).astype(np.uint8)
        if noise_std:
            self._raster._add_noise(image, noise_std, rng)
        return image

    def __del__(self):
        if getattr(self, "_renderer", None) is not None:
            self.close()
