"""CameraConnector: world to design. The robot's camera renders the world into the frames the
design sees.

The camera sits on the robot: its pose is the robot's pose moved ``mount_forward`` metres
along the heading, at ``mount_height`` above the floor, pitched by ``tilt``. Each capture
renders the world's current scene to an RGB888 image of the camera's resolution.
"""

import math

from ..errors import UsageError
from ..sim.scene import CameraPose

__all__ = ["CameraConnector", "camera_pose", "in_view", "make_renderer"]


def make_renderer(name, width, height, hfov, render3d=None):
    """The renderer ``camera.renderer`` names; a missing MuJoCo or OpenGL is a
    ``UsageError`` that says how to install them."""
    if name == "raster":
        from ..sim.camera import CameraRenderer

        return CameraRenderer(width, height, hfov)
    if name != "mujoco":
        raise ValueError(f"renderer must be 'raster' or 'mujoco', got {name!r}")
    from ..sim.render3d import MujocoRenderer, Render3DUnavailable

    try:
        renderer = MujocoRenderer(width, height, hfov, render3d)
        renderer.prepare()
    except Render3DUnavailable as exc:
        raise UsageError(f"camera.renderer = \"mujoco\": {exc}") from None
    return renderer


def camera_pose(robot_pose, *, height, forward=0.0, tilt=0.0):
    """The ``CameraPose`` of a camera mounted on a robot at ``robot_pose = (x, y, heading)``."""
    x, y, heading = robot_pose
    return CameraPose(
        x=x + forward * math.cos(heading),
        y=y + forward * math.sin(heading),
        heading=heading,
        height=height,
        tilt=tilt,
    )


def in_view(pose, hfov, px, py, radius):
    """Whether an upright cylinder at ``(px, py)`` is (at least partly) inside the horizontal
    field of view of a camera at ``pose``. Occlusion is not considered."""
    dx, dy = px - pose.x, py - pose.y
    dist = math.hypot(dx, dy)
    if dist <= radius:
        return True
    bearing = math.atan2(dy, dx) - pose.heading
    bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
    if abs(bearing) >= math.pi / 2:
        return False  # behind the camera
    return abs(bearing) - math.asin(radius / dist) < hfov / 2


class CameraConnector:
    """Renders what the robot's camera sees.

    Parameters
    ----------
    width, height : int
        Resolution of the captured frames.
    hfov : float
        Horizontal field of view, rad.
    mount_height, mount_forward, tilt : float
        The camera's mount on the robot (m, m, rad).
    noise_std : float
        Standard deviation of the sensor noise added by the renderer (8-bit levels).
    rng : numpy.random.Generator
        The noise's random stream (one per run, for determinism).
    renderer : str
        ``"raster"`` (``sim.camera.CameraRenderer``) or ``"mujoco"`` (``sim.render3d``).
    render3d : sim.render3d.Render3DOptions or None
        The 3D renderer's options (shadows, textures, lamps); None: its defaults.
    """

    def __init__(self, width, height, hfov, *, mount_height, mount_forward=0.0, tilt=0.0,
                 noise_std=0.0, rng=None, renderer="raster", render3d=None):
        self.width, self.height, self.hfov = width, height, hfov
        self.mount_height, self.mount_forward, self.tilt = mount_height, mount_forward, tilt
        self.noise_std = noise_std
        self.rng = rng
        self.renderer = make_renderer(renderer, width, height, hfov, render3d)

    def pose(self, robot_pose):
        return camera_pose(robot_pose, height=self.mount_height, forward=self.mount_forward,
                           tilt=self.tilt)

    def capture(self, scene, pose):
        """The RGB888 frame (height, width, 3) of ``scene`` seen from ``pose``."""
        return self.renderer.render(scene, pose, noise_std=self.noise_std, rng=self.rng)
