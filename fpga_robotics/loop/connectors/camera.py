"""CameraConnector: world to design. The robot's camera renders the world into the frames the
design sees.

The camera sits on the robot: its pose is the robot's pose moved ``mount_forward`` metres
along the heading, at ``mount_height`` above the floor, pitched by ``tilt``. Each capture
renders the world's current scene to an RGB888 image of the camera's resolution; with a sensor
model (``camera.sensor = "ov7670"``, ``make_sensor``) that image is the light reaching the
sensor, and the capture is what the OV7670 makes of it.
"""

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.pixel import COLOR_SELECT
from fpga_robotics.loop.connectors.base import (
    Connector,
    ConnectorError,
    Mount,
    Pin,
    check_number,
    refuse_unknown_keys,
    register,
)
from fpga_robotics.sim.camera.raster import CameraRenderer, focal_length, vertical_fov
from fpga_robotics.sim.camera.render3d import MujocoRenderer, Render3DUnavailable
from fpga_robotics.sim.camera.scene import CameraPose
from fpga_robotics.sim.camera.sensor import OV7670Sensor

__all__ = [
    "SENSOR_STREAM",
    "CameraConnector",
    "CameraParams",
    "ExposureDrift",
    "camera_pose",
    "in_view",
    "make_renderer",
    "make_sensor",
]

#: Correlation time of the exposure drift, s: a slow change (clouds, a lamp warming up).
DRIFT_TAU = 10.0


class ExposureDrift:
    """A slow random drift of the frames' brightness (``camera.exposure_drift = s``): the log
    of the gain is an Ornstein-Uhlenbeck process with standard deviation ``s`` and a
    correlation time of ``DRIFT_TAU``, stepped once a frame (exactly, whatever the frame
    rate) and starting at 1 (no change at frame 0)."""

    def __init__(self, std, frame_period, rng):
        self.std, self.rng = float(std), rng
        self.a = math.exp(-frame_period / DRIFT_TAU)
        self.b = self.std * math.sqrt(1.0 - self.a * self.a)
        self.log_gain = 0.0
        self.frames = 0

    def gain(self):
        """The gain of the next frame (advancing the process after the first frame)."""
        if self.frames:
            self.log_gain = self.a * self.log_gain + self.b * self.rng.standard_normal()
        self.frames += 1
        return math.exp(self.log_gain)

    def apply(self, rgb):
        """``rgb`` (uint8) times the next gain, rounded and clipped to 0..255."""
        g = self.gain()
        return np.clip(rgb.astype(np.float32) * np.float32(g) + np.float32(0.5), 0, 255).astype(
            np.uint8
        )


#: The sensor model's random stream is ``default_rng([seed, SENSOR_STREAM])`` (a further
#: camera's ``[seed, SENSOR_STREAM, index]``): its own, so that it shifts neither the world's
#: randomness nor the plain path's noise.
SENSOR_STREAM = 0x5E45


def make_sensor(cam, seed, further=None):
    """The sensor model a scenario's ``CameraConfig`` asks for (``None``: the plain path);
    ``further = (index, CameraParams)``: the same model for the rig's further camera
    ``index``, at its own size, frame rate and field of view."""
    if cam.sensor == "plain":
        return None
    stream, size = [seed, SENSOR_STREAM], (cam.width, cam.height, cam.hfov, cam.frame_period)
    if further is not None:
        index, p = further
        stream, size = [*stream, index], (p.width, p.height, p.hfov, p.frame_period)
    width, height, hfov, frame_period = size
    return OV7670Sensor(
        width,
        height,
        cam.ov7670,
        rng=np.random.default_rng(stream),
        frame_period=frame_period,
        focal_px=focal_length(width, hfov),
    )


def make_renderer(name, width, height, hfov, render3d=None):
    """The renderer ``camera.renderer`` names; a missing MuJoCo or OpenGL is a
    ``UsageError`` that says how to install them."""
    if name == "raster":
        return CameraRenderer(width, height, hfov)
    if name != "mujoco":
        raise ValueError(f"renderer must be 'raster' or 'mujoco', got {name!r}")

    try:
        renderer = MujocoRenderer(width, height, hfov, render3d)
        renderer.prepare()
    except Render3DUnavailable as exc:
        raise UsageError(f'camera.renderer = "mujoco": {exc}') from None
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


def in_view(pose, cam, px, py, radius, height):
    """Whether an upright cylinder at ``(px, py)``, ``radius`` wide and ``height`` tall on the
    floor, is (at least partly) in the image of a camera at ``pose`` (``cam``: its ``width``,
    ``height`` and ``hfov``), as the renderer draws it (``sim.camera.raster``): some column of
    the field of view meets its side at rows of the image. Occlusion is not considered."""
    dx, dy = px - pose.x, py - pose.y
    dist = math.hypot(dx, dy)
    if dist <= radius:
        return True
    bearing = math.atan2(dy, dx) - pose.heading
    bearing = (bearing + math.pi) % (2 * math.pi) - math.pi
    if abs(bearing) >= math.pi / 2:
        return False  # behind the camera
    half = math.asin(radius / dist)
    if abs(bearing) - half >= cam.hfov / 2:
        return False  # beside the field of view
    lo, hi = max(bearing - half, -cam.hfov / 2), min(bearing + half, cam.hfov / 2)
    # The columns from angle lo to hi meet the near side at depths that fall to the point of
    # it nearest the camera's plane and rise again: the least and greatest are among those.
    nearest = math.atan2(dist * math.sin(bearing), dist * math.cos(bearing) - radius)
    angles = [lo, hi] + ([nearest] if lo < nearest < hi else [])
    depths = [_hit_depth(dist, bearing, radius, a) for a in angles]
    near, far = min(depths), max(depths)
    # At depth p the side spans the elevations atan(-h / p) to atan((height - h) / p) (the
    # renderer's rows, tilt rotating each column's fan of rays); each end moves monotonically
    # with p, so the columns together show it from the lowest of those at near and far to
    # the highest, against the image's tilt -+ half its vertical field of view.
    lowest = min(math.atan2(-pose.height, near), math.atan2(-pose.height, far))
    highest = max(math.atan2(height - pose.height, p) for p in (near, far))
    half_vfov = vertical_fov(cam.width, cam.height, cam.hfov) / 2
    return lowest < pose.tilt + half_vfov and highest > pose.tilt - half_vfov


def _hit_depth(distance, bearing, radius, angle):
    """The depth (m along the camera's axis) at which the column ``angle`` (rad off the axis,
    left positive) meets the near side of an upright cylinder of ``radius`` whose axis stands
    ``distance`` from the camera at ``bearing``: the nearer root of the ray ``(p, p tan
    angle)`` on its circle (the silhouette's edge, where the ray only grazes it, included)."""
    cx, cy, slope = distance * math.cos(bearing), distance * math.sin(bearing), math.tan(angle)
    b, a = cx + cy * slope, 1 + slope * slope
    return (b - math.sqrt(max(0.0, b * b - a * (distance**2 - radius**2)))) / a


@dataclass(frozen=True)
class CameraParams:
    """The keys of a ``[[robot.sensors]]`` camera (one more than the ``[camera]`` one):
    ``resolution``, ``fps``, ``hfov_deg``, ``tilt_deg``, ``noise_std``, ``on`` (the name of the
    servo it is mounted on, or none: on the body), ``color`` (the colour select its port
    bundle gets), and for the checks ``target`` (the person it should keep in view) and
    ``centred_deg`` (how far off its axis that person may be and still count as centred)."""

    width: int = 160
    height: int = 120
    fps: float = 10.0
    hfov: float = math.radians(60.0)
    tilt: float = 0.0
    noise_std: float = 0.0
    on: str | None = None
    color: str = "red"
    target: str | None = None
    centred_deg: float = 10.0

    @property
    def frame_period(self):
        return 1.0 / self.fps


_CAMERA_KEYS = (
    "resolution",
    "fps",
    "hfov_deg",
    "tilt_deg",
    "noise_std",
    "on",
    "color",
    "target",
    "centred_deg",
)


def _resolution(text, where):
    parts = text.lower().split("x") if isinstance(text, str) else []
    if len(parts) == 2 and all(p.isdigit() for p in parts):
        w, h = int(parts[0]), int(parts[1])
        if 16 <= w <= 4096 and 16 <= h <= 4096:
            return w, h
    raise ConnectorError(
        f"{where}.resolution must look like WIDTHxHEIGHT (16..4096 each), e.g. 160x120; "
        f"got {text!r}"
    )


def _word(table, key, where, choices=None):
    value = table.get(key)
    if value is None:
        return None
    if not isinstance(value, str) or (choices is not None and value not in choices):
        shown = f"one of {', '.join(choices)}" if choices is not None else "a name"
        raise ConnectorError(f"{where}.{key} must be {shown}, got {value!r}")
    return value


@register
class CameraConnector(Connector):
    """Renders what the robot's camera sees: the connector of kind ``camera``, bound to the
    design's pixel stream (``pixels``: RGB444 with first/last flags, docs/contract.md) and
    colour select. Scenarios configure it with the ``[camera]`` table (docs/scenarios.md);
    the closed loop streams each capture into the design, in frames (compressed timing) or
    pixel by pixel on the design clock with the sensor's blanking (real-clock timing).

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
    sensor : fpga_robotics.sim.camera.sensor.OV7670Sensor or None
        The sensor model the rendered frames go through (``make_sensor``); ``None``: the
        plain path (the rendered frame plus ``noise_std``). Its state (exposure, gains) is
        ``sensor_state()``.
    turn_rate : callable or None
        Returns the robot's turn rate (rad/s) at the capture, for the sensor's motion blur.
    yaw_offset : float
        The mount's yaw off the robot's heading, rad (a camera knocked off its pose).
    drift : ExposureDrift or None
        A slow random drift of the frames' brightness (``camera.exposure_drift``).
    renderer : str
        ``"raster"`` (``sim.camera.CameraRenderer``) or ``"mujoco"`` (``sim.render3d``).
    render3d : sim.render3d.Render3DOptions or None
        The 3D renderer's options (shadows, textures, lamps); None: its defaults.
    """

    def __init__(
        self,
        width,
        height,
        hfov,
        *,
        mount_height,
        mount_forward=0.0,
        tilt=0.0,
        noise_std=0.0,
        rng=None,
        sensor=None,
        turn_rate=None,
        yaw_offset=0.0,
        drift=None,
        renderer="raster",
        render3d=None,
    ):
        self.name, self.params, self.world = "camera", None, None
        self.width, self.height, self.hfov = width, height, hfov
        self.mount_height, self.mount_forward, self.tilt = mount_height, mount_forward, tilt
        self.noise_std = noise_std
        self.rng = rng
        self.renderer = make_renderer(renderer, width, height, hfov, render3d)
        self.sensor, self.turn_rate = sensor, turn_rate
        self.yaw_offset, self.drift = yaw_offset, drift

    kind = "camera"
    pins: ClassVar[dict] = {"pixels": Pin("in", 14), "color_sel": Pin("in", 3)}
    #: Runs in compressed timing: a frame through the design's channel on its port bundle.
    frame_level = True

    @classmethod
    def parse(cls, table, where):
        """A ``[[robot.sensors]]`` camera's keys (``CameraParams``)."""
        refuse_unknown_keys(
            table, _CAMERA_KEYS, where, cls.kind, f"{', '.join(_CAMERA_KEYS)} and the mount"
        )
        width, height = _resolution(table.get("resolution", "160x120"), where)
        color = _word(table, "color", where, tuple(COLOR_SELECT)) or "red"
        return CameraParams(
            width=width,
            height=height,
            fps=check_number(table, "fps", 10.0, where, lo=0, hi=240, lo_open=True),
            hfov=math.radians(
                check_number(table, "hfov_deg", 60.0, where, lo=1, hi=170, unit="deg")
            ),
            tilt=math.radians(
                check_number(table, "tilt_deg", 0.0, where, lo=-60, hi=60, unit="deg")
            ),
            noise_std=check_number(table, "noise_std", 0.0, where, lo=0, hi=64),
            on=_word(table, "on", where),
            color=color,
            target=_word(table, "target", where),
            centred_deg=check_number(
                table, "centred_deg", 10.0, where, lo=0, hi=90, unit="deg", lo_open=True
            ),
        )

    @property
    def mount(self):
        """Where the camera sits (``base.Mount``), from the constructor's fields."""
        return Mount(forward=self.mount_forward, height=self.mount_height, yaw=self.yaw_offset)

    def pose(self, robot_pose, pitch_at=None):
        """The camera's pose on a robot at ``robot_pose``; ``pitch_at(heading)`` (rad, e.g.
        ``World.camera_pitch``: the slope under the robot) adds to the mount's tilt for the
        heading the camera faces, its yaw offset included."""
        pose = camera_pose(
            robot_pose, height=self.mount_height, forward=self.mount_forward, tilt=self.tilt
        )
        heading = pose.heading + self.yaw_offset
        pitch = pitch_at(heading) if pitch_at is not None else 0.0
        return replace(pose, heading=heading, tilt=pose.tilt + pitch)

    def capture(self, scene, pose, turn_rate=None):
        """The RGB888 frame (height, width, 3) of ``scene`` seen from ``pose``; ``turn_rate``:
        the camera's (rad/s, the sensor model's motion blur), else the callback's."""
        if self.sensor is not None:  # the drift is in the light that reaches the sensor
            rendered = self.renderer.render(scene, pose)
            if turn_rate is None:
                turn_rate = self.turn_rate() if self.turn_rate is not None else 0.0
            light = rendered if self.drift is None else self.drift.apply(rendered)
            return self.sensor.process(light, turn_rate)
        rgb = self.renderer.render(scene, pose, noise_std=self.noise_std, rng=self.rng)
        return rgb if self.drift is None else self.drift.apply(rgb)

    def sensor_state(self):
        """The sensor model's exposure, gain and white-balance gains; None on the plain path."""
        return self.sensor.state() if self.sensor is not None else None
