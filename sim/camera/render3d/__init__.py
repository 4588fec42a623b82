"""A 3D camera renderer (MuJoCo, off-screen): textures, lights with shadows, people with
bodies and a walking gait; the same call as ``sim.camera.CameraRenderer``. Needs the
optional install ``pip install -e ".[realistic]"`` (docs/render3d.md)."""

from .body import cycle_length, gait_angles
from .options import FLOORS, Lamp, Render3DOptions
from .renderer import INSTALL_HINT, MujocoRenderer, Render3DUnavailable, load_mujoco

__all__ = [
    "FLOORS",
    "INSTALL_HINT",
    "Lamp",
    "MujocoRenderer",
    "Render3DOptions",
    "Render3DUnavailable",
    "cycle_length",
    "gait_angles",
    "load_mujoco",
]
