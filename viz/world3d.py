"""The world in 3D in the viewer: the room, furniture, people and the robot as 3D entities,
and the robot's camera as a pinhole with its frustum and the current frame on it.

Fed by ``FrameRecord.scene`` and ``camera_pose`` (a record without them logs nothing here).
World coordinates as the physics has them (x, y on the floor, z up, metres). The walls and
floor are logged once, static; the furniture at the first frame and again when a piece
leaves the room; the robot, the people and the camera's pose every frame. The camera's
pinhole sits at ``camera``, the parent of the camera frame ``camera/raw`` that the recorder
logs, so the frame appears on the frustum without being logged twice.
"""

import math

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from fpga_robotics.sim.camera.render3d.body import (
    REFERENCE_HEIGHT,
    REFERENCE_RADIUS,
    body_colors,
    gait_angles,
    person_height,
)
from fpga_robotics.sim.camera.render3d.floor_patches import LIFT, triangulate

from . import paths as P

__all__ = ["CAMERA", "ROBOT", "ROOM", "WORLD3D", "World3D", "camera_rotation", "world3d_view"]

WORLD3D = "world3d"
ROOM = "world3d/room"
FURNITURE = "world3d/furniture"
FLOOR = "world3d/floor"
#: What is painted or taped on the floor (``Scene.floor_patches``: terrain, line tracks).
FLOOR_MARKS = "world3d/floor/marks"
PEOPLE = "world3d/people"
ROBOT = "world3d/robot"
#: The pinhole: the parent of the camera frame (``viz.paths.CAMERA_RAW``).
CAMERA = P.CAMERA_RAW.rsplit("/", 1)[0]

_ROBOT_COLOR = (60, 160, 255)
_WALL_THICKNESS = 0.05


def _u8(color):
    return tuple(round(255 * min(1.0, max(0.0, c))) for c in color)


def camera_rotation(heading, tilt):
    """Columns: the camera's right, down and forward axes in the world (rerun's RDF camera)."""
    ch, sh, ct, st = math.cos(heading), math.sin(heading), math.cos(tilt), math.sin(tilt)
    forward = np.array([ch * ct, sh * ct, st])
    right = np.array([sh, -ch, 0.0])
    down = -np.cross(right, forward)
    return np.column_stack([right, down, forward])


def _wall_boxes(walls):
    """Centres, half sizes, yaw angles and colours of the walls as thin boxes."""
    centers, halves, quats, colors = [], [], [], []
    for w in walls:
        ex, ey = w.x1 - w.x0, w.y1 - w.y0
        length = math.hypot(ex, ey)
        if length == 0.0:
            continue
        a = math.atan2(ey, ex)
        centers.append(((w.x0 + w.x1) / 2, (w.y0 + w.y1) / 2, w.height / 2))
        halves.append((length / 2, _WALL_THICKNESS / 2, w.height / 2))
        quats.append(rr.Quaternion(xyzw=(0.0, 0.0, math.sin(a / 2), math.cos(a / 2))))
        colors.append(_u8(w.color))
    return centers, halves, quats, colors


def _floor_marks(patches):
    """One mesh of the floor's patches (``[(polygon, colour)]``), each cut into triangles,
    just above the floor as the 3D renderer lays them."""
    vertices, triangles, colors = [], [], []
    for polygon, color in patches:
        for tri in triangulate(polygon):
            triangles.append(range(len(vertices), len(vertices) + 3))
            vertices += [(x, y, LIFT) for x, y in tri]
            colors += [_u8(color)] * 3
    return rr.Mesh3D(vertex_positions=vertices, triangle_indices=triangles, vertex_colors=colors)


def _limbs(cyl):
    """A person as thick line segments (legs, torso, arms) and a head, in world coordinates,
    with the gait's hip and shoulder swing: (strips, radii, colours), (head centre, radius,
    colour)."""
    h = person_height(cyl.bands)
    s, k = h / REFERENCE_HEIGHT, cyl.radius / REFERENCE_RADIUS
    colors = body_colors(cyl.bands, h)
    angles = gait_angles(cyl.walked, cyl.speed, h)
    c, sn = math.cos(cyl.facing), math.sin(cyl.facing)

    def world(x, y, z):
        return (cyl.x + c * x - sn * y, cyl.y + sn * x + c * y, z)

    strips, radii, cols = [], [], []
    for side, y in (("l", 1.0), ("r", -1.0)):
        hip = (0.0, 0.082 * k * y, 0.86 * s)
        a = angles["hip_" + side]
        knee_bend = angles["knee_" + side]
        knee = (hip[0] + 0.4 * s * math.sin(a), hip[1], hip[2] - 0.4 * s * math.cos(a))
        b = a - knee_bend
        foot = (knee[0] + 0.42 * s * math.sin(b), hip[1], knee[2] - 0.42 * s * math.cos(b))
        strips.append([world(*hip), world(*knee), world(*foot)])
        radii.append(0.07 * k)
        cols.append(_u8(colors.trousers))
        sh = (0.0, 0.158 * k * y, 1.40 * s)
        a = angles["shoulder_" + side]
        hand = (sh[0] + 0.6 * s * math.sin(a), sh[1], sh[2] - 0.6 * s * math.cos(a))
        strips.append([world(*sh), world(*hand)])
        radii.append(0.042 * k)
        cols.append(_u8(colors.shirt))
    strips.append([world(0.0, 0.0, 0.9 * s), world(0.0, 0.0, 1.38 * s)])
    radii.append(0.12 * k)
    cols.append(_u8(colors.shirt))
    head = (world(0.0, 0.0, 1.63 * s), 0.11 * max(k, s), _u8(colors.skin))
    return (strips, radii, cols), head


def eye_position(bounds, wall_height=0.0):
    """Where the 3D view's eye starts and what it looks at, for a room of ``bounds``
    ``(xmin, ymin, xmax, ymax)`` with walls ``wall_height`` high: above and in front of the
    room (over its near wall), looking at its middle, high enough that the near wall hides at
    most a tenth of the room's depth (from a fixed height, a 2.5 m wall hides all of a small
    room)."""
    xmin, ymin, xmax, ymax = (float(v) for v in bounds)
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    depth = ymax - ymin
    size = max(xmax - xmin, depth)
    back = 0.1 * depth
    # Over the near wall's top the line of sight meets the floor back * H / (z - H) inside
    # the room: from z = 2.5 H, a fifteenth of its depth.
    z = max(1.2 * size, 2.5 * wall_height)  # and far enough to take in the whole room
    return (cx, ymin - back, z), (cx, cy, 0.0)


def world3d_view(bounds=None, wall_height=0.0):
    """The viewer's 3D view: the world and the camera frame on its pinhole (not the other
    images under the camera, such as the filtered frame). With the room's ``bounds``
    ``(xmin, ymin, xmax, ymax)`` and its walls' height the eye starts above and in front of
    the room (over its near wall), looking at its middle (``eye_position``)."""
    eye = None
    if bounds is not None:
        position, target = eye_position(bounds, wall_height)
        eye = rrb.EyeControls3D(position=position, look_target=target, eye_up=(0.0, 0.0, 1.0))
    return rrb.Spatial3DView(
        origin="/",
        name="World (3D)",
        # Further cameras (viz.cameras): each pinhole with its image, at cameras/<name>.
        contents=[f"+ /{WORLD3D}/**", f"+ /{CAMERA}", f"+ /{P.CAMERA_RAW}", "+ /cameras/**"],
        eye_controls=eye,
    )


class World3D:
    """Logs the 3D world of each ``FrameRecord`` to ``stream`` (see the module's doc)."""

    def __init__(self, stream):
        self._stream = stream
        self._walls = None
        self._pinhole = None
        #: The room's walls' height as drawn, for the view's eye (``eye_position``).
        self.wall_height = 0.0

    def _log_walls(self, scene, stream):
        log = stream.log
        log(WORLD3D, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        room = [w for w in scene.walls if w.kind == "room"]
        rest = [w for w in scene.walls if w.kind != "room"]
        self.wall_height = max((w.height for w in room), default=0.0)
        # The room stays; the furniture is on the timeline (set by the caller), since a piece
        # may leave the room during the run: static, it would stay drawn, or vanish from the
        # frames before its removal too.
        for path, walls, static in ((ROOM, room, True), (FURNITURE, rest, False)):
            if walls:
                centers, halves, quats, colors = _wall_boxes(walls)
                log(
                    path,
                    rr.Boxes3D(
                        centers=centers,
                        half_sizes=halves,
                        quaternions=quats,
                        colors=colors,
                        fill_mode="solid",
                    ),
                    static=static,
                )
            elif not static:
                log(path, rr.Clear(recursive=False))
        xs = [v for w in room for v in (w.x0, w.x1)] or [0.0, 1.0]
        ys = [v for w in room for v in (w.y0, w.y1)] or [0.0, 1.0]
        log(
            FLOOR,
            rr.Boxes3D(
                centers=[((min(xs) + max(xs)) / 2, (min(ys) + max(ys)) / 2, -0.01)],
                half_sizes=[((max(xs) - min(xs)) / 2, (max(ys) - min(ys)) / 2, 0.01)],
                colors=[_u8(scene.floor_color)],
                fill_mode="solid",
            ),
            static=True,
        )
        if scene.floor_patches:
            log(FLOOR_MARKS, _floor_marks(scene.floor_patches), static=True)
        self._walls = scene.walls

    def _log_pinhole(self, width, height, hfov, stream):
        f = (width / 2) / math.tan(hfov / 2)
        stream.log(
            CAMERA,
            rr.Pinhole(
                focal_length=f,
                width=width,
                height=height,
                camera_xyz=rr.ViewCoordinates.RDF,
                image_plane_distance=0.6,
            ),
            static=True,
        )
        self._pinhole = (width, height, hfov)

    def log_frame(self, record, frame, t, stream=None):
        """Log ``record``'s robot, people and camera pose at ``frame`` and sim time ``t``
        (``viz.columns.time_ns``), to ``stream`` when given (``viz.frame_calls``)."""
        scene, pose = record.scene, record.camera_pose
        if scene is None or pose is None:
            return
        s = self._stream if stream is None else stream
        s.set_time("frame", sequence=frame)
        s.set_time("sim_time", duration=t)
        if scene.walls is not self._walls:
            self._log_walls(scene, s)
        height, width = record.camera_rgb.shape[:2]
        if self._pinhole != (width, height, record.camera_hfov):
            self._log_pinhole(width, height, float(record.camera_hfov), s)
        s.log(
            CAMERA,
            rr.Transform3D(
                translation=(pose.x, pose.y, pose.height),
                mat3x3=camera_rotation(pose.heading, pose.tilt),
            ),
        )
        r = max(float(record.robot_radius), 0.05)
        s.log(
            ROBOT,
            rr.Cylinders3D(
                lengths=[max(pose.height, 0.1)],
                radii=[r],
                centers=[(record.robot_x, record.robot_y, max(pose.height, 0.1) / 2)],
                colors=[_ROBOT_COLOR],
                fill_mode="solid",
            ),
        )
        strips, radii, colors, heads, head_r, head_c = [], [], [], [], [], []
        for cyl in scene.cylinders:
            (st, ra, co), (hc, hr, hcol) = _limbs(cyl)
            strips += st
            radii += ra
            colors += co
            heads.append(hc)
            head_r.append(hr)
            head_c.append(hcol)
        s.log(f"{PEOPLE}/bodies", rr.LineStrips3D(strips, radii=radii, colors=colors))
        s.log(f"{PEOPLE}/heads", rr.Points3D(heads, radii=head_r, colors=head_c))
