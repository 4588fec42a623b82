"""CameraConnector: world to design. The robot's camera renders the world into the frames the
design sees.

The camera sits on the robot: its pose is the robot's pose moved ``mount_forward`` metres
along the heading, at ``mount_height`` above the floor, pitched by ``tilt``. Each capture
renders the world's current scene to an RGB888 image of the camera's resolution; with a sensor
model (``camera.sensor = "ov7670"``, ``make_sensor``) that image is the light reaching the
sensor, and the capture is what the OV7670 makes of it.
"""

import math

import numpy as np

from ..sim.scene import CameraPose

__all__ = ["SENSOR_STREAM", "CameraConnector", "camera_pose", "in_view", "make_sensor"]

#: The sensor model's random stream is ``default_rng([seed, SENSOR_STREAM])``: its own, so that
#: it shifts neither the world's randomness nor the plain path's noise.
SENSOR_STREAM = 0x5E45


def make_sensor(cam, seed):
    """The sensor model a scenario's ``CameraConfig`` asks for (``None``: the plain path)."""
    if cam.sensor == "plain":
        return None
    from ..sim.camera import focal_length
    from ..sim.sensor import OV7670Sensor

    return OV7670Sensor(cam.width, cam.height, cam.ov7670,
                        rng=np.random.default_rng([seed, SENSOR_STREAM]),
                        frame_period=cam.frame_period, focal_px=focal_length(cam.width, cam.hfov))


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
    sensor : fpga_robotics.sim.sensor.OV7670Sensor or None
        The sensor model the rendered frames go through (``make_sensor``); ``None``: the
        plain path (the rendered frame plus ``noise_std``). Its state (exposure, gains) is
        ``sensor_state()``.
    turn_rate : callable or None
        Returns the robot's turn rate (rad/s) at the capture, for the sensor's motion blur.
    """

    def __init__(self, width, height, hfov, *, mount_height, mount_forward=0.0, tilt=0.0,
                 noise_std=0.0, rng=None, sensor=None, turn_rate=None):
        from ..sim.camera import CameraRenderer

        self.width, self.height, self.hfov = width, height, hfov
        self.mount_height, self.mount_forward, self.tilt = mount_height, mount_forward, tilt
        self.noise_std = noise_std
        self.rng = rng
        self.renderer = CameraRenderer(width, height, hfov)
        self.sensor, self.turn_rate = sensor, turn_rate

    def pose(self, robot_pose):
        return camera_pose(robot_pose, height=self.mount_height, forward=self.mount_forward,
                           tilt=self.tilt)

    def capture(self, scene, pose):
        """The RGB888 frame (height, width, 3) of ``scene`` seen from ``pose``."""
        if self.sensor is not None:
            return self._sense(self.renderer.render(scene, pose))
        return self.renderer.render(scene, pose, noise_std=self.noise_std, rng=self.rng)

    def _sense(self, rgb):
        """The sensor model's frame of the rendered (noise-free) ``rgb``."""
        return self.sensor.process(rgb, self.turn_rate() if self.turn_rate is not None else 0.0)

    def sensor_state(self):
        """The sensor model's exposure, gain and white-balance gains; None on the plain path."""
        return self.sensor.state() if self.sensor is not None else None
