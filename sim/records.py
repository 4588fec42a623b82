"""What the closed loop produces, frame by frame: the data the viewer and the summary read.

The closed loop (``fpga_robotics.loop``) fills these; ``fpga_robotics.viz`` logs them to rerun.
Positions are in metres in the world frame (x right, y up, top-down view), headings in radians
counter-clockwise from +x, times in seconds of simulated time.
"""

from dataclasses import dataclass, field

import numpy as np

from .backends.base import FrameResult

__all__ = ["CameraView", "FrameRecord", "PersonState", "SensorReading", "WorldMap"]


@dataclass(frozen=True)
class WorldMap:
    """Static geometry of a scenario, drawn once in the top-down map."""

    walls: list  # [((x0, y0), (x1, y1)), ...] wall segments
    obstacles: list  # [[(x, y), ...], ...] furniture polygons (closed, counter-clockwise)
    obstacle_colors: list  # [(r, g, b), ...] one uint8 colour per obstacle
    bounds: tuple  # (xmin, ymin, xmax, ymax)
    terrain: list = field(default_factory=list)  # [[(x, y), ...], ...] floor patch outlines
    terrain_colors: list = field(default_factory=list)  # [(r, g, b), ...] uint8, one each
    #: Floor markings (``[[room.lines]]``): centrelines ``[[(x, y), ...], ...]`` (a closed
    #: line repeats its first point at the end), their widths (m) and uint8 colours.
    lines: list = field(default_factory=list)
    line_widths: list = field(default_factory=list)
    line_colors: list = field(default_factory=list)


@dataclass(frozen=True)
class PersonState:
    name: str
    x: float
    y: float
    radius: float
    is_target: bool


@dataclass(frozen=True, eq=False)
class FrameRecord:
    """One camera frame of the closed loop: what the FPGA saw, decided, and what the robot did."""

    frame: int  # frame index, 0-based
    sim_time: float  # simulated time of the capture, s
    camera_rgb: np.ndarray  # (H, W, 3) uint8, the rendered camera image as captured
    color_sel: int  # 3-bit colour select in force for this frame
    result: FrameResult  # the design's outputs for this frame
    robot_x: float
    robot_y: float
    robot_heading: float
    robot_v: float  # measured linear speed of the robot, m/s
    robot_w: float  # measured angular speed of the robot, rad/s
    cmd_v: float  # V commanded by the design's DPS through the robot's kinematics, m/s
    cmd_w: float  # W commanded, rad/s
    camera_hfov: float  # horizontal field of view, rad
    people: list = field(default_factory=list)  # [PersonState, ...]
    target_distance: float | None = None  # robot centre to target person centre, m
    target_in_view: bool = False  # the target person is geometrically in the camera's view
    events: list = field(default_factory=list)  # ["target found", "collision with wall", ...]
    shadow_result: FrameResult | None = None  # a shadow design's outputs on the same frame
    # The world in 3D for the viewer (viz.world3d): the scene the camera saw, the camera's
    # pose and the robot's radius (m).
    scene: object = None  # sim.scene.Scene
    camera_pose: object = None  # sim.scene.CameraPose
    robot_radius: float = 0.0
    # Real-clock timing: what each connector measured and what the design saw at its pins,
    # {name: SensorReading}, and the design's outputs beyond FollowTarget's ({name: value}:
    # distance_mm, obstacle, line_seen).
    sensors: dict = field(default_factory=dict)
    design_extra: dict = field(default_factory=dict)
    shadow_extra: dict = field(default_factory=dict)  # a shadow design's, as design_extra
    # Further cameras ([[robot.sensors]] kind = "camera"): {name: CameraView}, each its
    # latest capture at this frame's instant.
    cameras: dict = field(default_factory=dict)
    # Whether the design takes the camera's frames (False: a design without a camera port,
    # the camera only films the run for the viewer).
    camera_input: bool = True


@dataclass(frozen=True)
class SensorReading:
    """One connector's reading for the viewer: its ``kind``, its measurement values
    (``Connector.measurement``), and what to draw on the map: ``points`` (x, y) with a
    0/1 ``state`` each (line sensors: over the line or not) and ``rays`` ((x0, y0), (x1, y1))
    (an ultrasound's measured range)."""

    kind: str
    values: dict
    points: tuple = ()
    states: tuple = ()
    rays: tuple = ()
    #: Height (m) of the points in the 3D view (a LIDAR's scan plane).
    height: float = 0.0
    #: A LIDAR's last whole revolution (``sim.world.lidar.Revolution``), None for others.
    scan: object = None


@dataclass(frozen=True, eq=False)
class CameraView:
    """A further camera's latest capture for the viewer: the image, where it was taken
    (``CameraPose``), its field of view (rad), when (s), and what the design's channel on it
    made of it (``found``, ``centroid_x``; None when the channel has no such output)."""

    rgb: np.ndarray
    pose: object
    hfov: float
    sim_time: float
    found: bool | None = None
    centroid_x: int | None = None
