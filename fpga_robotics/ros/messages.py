"""A closed-loop frame as standard ROS 2 messages, serialised to CDR (no ROS installation).

``FrameMessages(geometry).encode(record)`` turns one ``FrameRecord`` into ``(topic, ns, cdr)``
triples: the same bytes go into a bag (``bag_writer``) and out on the live Foxglove server
(``foxglove_live``). Everything is stamped in simulated time (nanoseconds from the run's
start). Frames: ``odom`` (the world: x, y on the floor, z up, headings counter-clockwise
from +x, as in ROS REP 103), ``base_link`` (the robot), ``camera_link`` (the camera on its
mount, x forward, pitched by the camera's tilt) and its child ``camera_optical_link`` (x
right, y down, z into the image: the frame of the images and CameraInfo). An output the design lacks (None) is not
published for that frame. Each further camera (``FrameRecord.cameras``) has its own topics,
``/cameras/<name>/image_raw`` and ``camera_info`` (``camera_topics``), stamped at its own
capture instant and written once per capture, in its frame ``<name>_optical_link``, a child
of ``<name>_link`` (placed in ``odom`` on ``/tf``: on a servo it turns with the horn).
"""

import math
import re
from dataclasses import dataclass

import numpy as np
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.sim.camera.raster import focal_length

from ..sim.world.config import parse_world_config
from ..sim.world.kinematics import dps_to_twist

__all__ = [
    "EXTRA_PREFIX",
    "EXTRA_TYPE",
    "TOPICS",
    "TYPESTORE",
    "CameraGeometry",
    "FrameMessages",
    "camera_geometry",
    "camera_topics",
    "extra_topic",
    "msgdef",
    "topic_type",
]

#: The typestore every message is built and read with (ROS 2 Humble definitions).
TYPESTORE = get_typestore(Stores.ROS2_HUMBLE)

#: Every topic a run publishes, with its message type, in the order written per frame.
TOPICS = {
    "/clock": "rosgraph_msgs/msg/Clock",
    "/camera/image_raw": "sensor_msgs/msg/Image",
    "/camera/camera_info": "sensor_msgs/msg/CameraInfo",
    "/fpga/filtered/image": "sensor_msgs/msg/Image",
    "/fpga/found": "std_msgs/msg/Bool",
    "/fpga/proximity": "std_msgs/msg/UInt8",
    "/fpga/centroid_x": "std_msgs/msg/UInt16",
    "/fpga/centroid_leds": "std_msgs/msg/UInt8",
    "/fpga/wheel_dps": "std_msgs/msg/Int16MultiArray",
    "/cmd_vel": "geometry_msgs/msg/Twist",
    "/odom": "nav_msgs/msg/Odometry",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/people": "visualization_msgs/msg/MarkerArray",
}


def camera_topics(name):
    """A further camera's topics with their message types."""
    return {
        f"/cameras/{name}/image_raw": "sensor_msgs/msg/Image",
        f"/cameras/{name}/camera_info": "sensor_msgs/msg/CameraInfo",
    }


#: A design's extra outputs (every output no connector reads): one topic each, named
#: ``EXTRA_PREFIX + name``, of type ``EXTRA_TYPE`` (a signed 64-bit integer holds any value
#: of a port up to 63 bits, signed or not), published from the frame they first appear in.
EXTRA_PREFIX = "/design/extra/"
EXTRA_TYPE = "std_msgs/msg/Int64"


def extra_topic(name):
    """The topic of extra output ``name`` (characters a ROS name cannot hold become ``_``)."""
    token = re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9_]", "_", name)).strip("_") or "output"
    if token[0].isdigit():
        token = "o" + token
    return EXTRA_PREFIX + token


def topic_type(topic):
    """The message type of a topic the runs publish (``TOPICS`` or an extra output's)."""
    return TOPICS.get(topic) or (EXTRA_TYPE if topic.startswith(EXTRA_PREFIX) else None)


_T = TYPESTORE.types
_Time = _T["builtin_interfaces/msg/Time"]
_Duration = _T["builtin_interfaces/msg/Duration"]
_Header = _T["std_msgs/msg/Header"]
_Vector3 = _T["geometry_msgs/msg/Vector3"]
_Point = _T["geometry_msgs/msg/Point"]
_Quaternion = _T["geometry_msgs/msg/Quaternion"]
_Pose = _T["geometry_msgs/msg/Pose"]
_Twist = _T["geometry_msgs/msg/Twist"]
_ColorRGBA = _T["std_msgs/msg/ColorRGBA"]
_MultiArrayLayout = _T["std_msgs/msg/MultiArrayLayout"]
_MultiArrayDimension = _T["std_msgs/msg/MultiArrayDimension"]

# Filtered frame: packed RGB444 to RGB888, each 4-bit channel v as v * 17 (0..255).
_RGB444_LUT = np.zeros((1 << 12, 3), np.uint8)
_codes = np.arange(1 << 12)
for _i, _shift in enumerate((8, 4, 0)):
    _RGB444_LUT[:, _i] = ((_codes >> _shift) & 0xF) * 17
del _codes, _i, _shift

_TARGET_RGBA = (1.0, 0.25, 0.25, 1.0)
_PERSON_RGBA = (0.65, 0.65, 0.75, 1.0)
_PERSON_HEIGHT = 1.75  # the marker's height, m (drawn standing on the floor)

# A camera's optical frame (REP 103: x right, y down, z into the image) in its link frame
# (x forward, z up): Image and CameraInfo are stamped with it, as tools that project with
# CameraInfo expect.
_OPTICAL = _T["geometry_msgs/msg/Transform"](
    translation=_Vector3(x=0.0, y=0.0, z=0.0),
    rotation=_Quaternion(x=-0.5, y=0.5, z=-0.5, w=0.5),
)


def _optical(stamp, link):
    """The ``/tf`` transform from the camera frame ``link`` to its optical frame."""
    return _T["geometry_msgs/msg/TransformStamped"](
        header=_Header(stamp=stamp, frame_id=link),
        child_frame_id=_optical_frame(link),
        transform=_OPTICAL,
    )


def _optical_frame(link):
    """``camera_link`` -> ``camera_optical_link``."""
    return link.removesuffix("_link") + "_optical_link"


def msgdef(msgtype):
    """The ROS 2 ``.msg`` text of ``msgtype`` with its dependencies (the ``ros2msg`` schema
    bags and Foxglove carry)."""
    return TYPESTORE.generate_msgdef(msgtype, ros_version=2)[0]


@dataclass(frozen=True)
class CameraGeometry:
    """What the messages need to know about the robot and its camera."""

    width: int
    height: int
    hfov: float  # rad
    mount_forward: float  # camera ahead of the robot's centre, m
    mount_height: float  # above the floor, m
    tilt: float  # rad, positive looks up (as sim.scene.CameraPose)
    wheel_radius: float  # m
    wheel_separation: float  # m


def camera_geometry(scenario):
    """The ``CameraGeometry`` of a scenario: its camera, on its robot (mount values the
    scenario leaves unset are the robot's, as in the closed loop)."""
    spec = parse_world_config(scenario.world).robot.spec
    cam = scenario.camera
    return CameraGeometry(
        width=cam.width,
        height=cam.height,
        hfov=cam.hfov,
        mount_forward=cam.mount_forward if cam.mount_forward is not None else spec.camera_forward,
        mount_height=cam.mount_height if cam.mount_height is not None else spec.camera_height,
        tilt=cam.tilt if cam.tilt is not None else spec.camera_tilt,
        wheel_radius=spec.wheel_radius,
        wheel_separation=spec.wheel_separation,
    )


def _stamp(ns):
    return _Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def _yaw(angle):
    return _Quaternion(x=0.0, y=0.0, z=math.sin(angle / 2), w=math.cos(angle / 2))


def _pitch(angle):
    return _Quaternion(x=0.0, y=math.sin(angle / 2), z=0.0, w=math.cos(angle / 2))


class FrameMessages:
    """Builds and serialises the messages of each frame; constant parts built once."""

    def __init__(self, geometry):
        self.geometry = g = geometry
        f = focal_length(g.width, g.hfov)
        cx, cy = g.width / 2, g.height / 2
        self._camera_info = {
            "height": g.height,
            "width": g.width,
            "distortion_model": "plumb_bob",
            "d": np.zeros(5),
            "k": np.array([f, 0, cx, 0, f, cy, 0, 0, 1], float),
            "r": np.eye(3).ravel(),
            "p": np.array([f, 0, cx, 0, 0, f, cy, 0, 0, 0, 1, 0], float),
            "binning_x": 0,
            "binning_y": 0,
            "roi": _T["sensor_msgs/msg/RegionOfInterest"](
                x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
            ),
        }
        self._mount = _T["geometry_msgs/msg/Transform"](
            translation=_Vector3(x=g.mount_forward, y=0.0, z=g.mount_height),
            rotation=_pitch(-g.tilt),
        )  # about +y (left): a positive pitch looks down
        self._dps_layout = _MultiArrayLayout(
            dim=[_MultiArrayDimension(label="left,right", size=2, stride=2)], data_offset=0
        )
        self._zero = _Vector3(x=0.0, y=0.0, z=0.0)
        #: Topic -> message type of every topic written so far (TOPICS and cameras' ones).
        self.topic_types = dict(TOPICS)
        self._captured = {}  # further camera -> the capture instant last written
        self._covariance = np.zeros(36)
        self._ser = TYPESTORE.serialize_cdr

    def _image(self, header, rgb):
        h, w = rgb.shape[:2]
        return _T["sensor_msgs/msg/Image"](
            header=header,
            height=h,
            width=w,
            encoding="rgb8",
            is_bigendian=0,
            step=w * 3,
            data=np.ascontiguousarray(rgb, np.uint8).reshape(-1),
        )

    def _info_of(self, header, width, height, hfov):
        f = focal_length(width, hfov)
        return _T["sensor_msgs/msg/CameraInfo"](
            header=header,
            **{
                **self._camera_info,
                "height": height,
                "width": width,
                "k": np.array([f, 0, width / 2, 0, f, height / 2, 0, 0, 1], float),
                "p": np.array([f, 0, width / 2, 0, 0, f, height / 2, 0, 0, 0, 1, 0], float),
            },
        )

    def _further_cameras(self, record):
        """Each further camera's image, calibration and place, once per capture."""
        out = []
        for name, view in (getattr(record, "cameras", None) or {}).items():
            if self._captured.get(name) == view.sim_time:
                continue
            self._captured[name] = view.sim_time
            self.topic_types.update(camera_topics(name))
            stamp = _stamp(round(view.sim_time * 1e9))
            header = _Header(stamp=stamp, frame_id=_optical_frame(f"{name}_link"))
            h, w = view.rgb.shape[:2]
            p = view.pose
            # Yaw about z, then the tilt about the camera's y (a positive tilt looks up).
            cy, sy = math.cos(p.heading / 2), math.sin(p.heading / 2)
            cp, sp = math.cos(-p.tilt / 2), math.sin(-p.tilt / 2)
            rotation = _Quaternion(x=-sy * sp, y=cy * sp, z=sy * cp, w=cy * cp)
            place = _T["geometry_msgs/msg/TransformStamped"](
                header=_Header(stamp=stamp, frame_id="odom"),
                child_frame_id=f"{name}_link",
                transform=_T["geometry_msgs/msg/Transform"](
                    translation=_Vector3(x=float(p.x), y=float(p.y), z=float(p.height)),
                    rotation=rotation,
                ),
            )
            out += [
                (f"/cameras/{name}/image_raw", self._image(header, view.rgb)),
                (f"/cameras/{name}/camera_info", self._info_of(header, w, h, view.hfov)),
                (
                    "/tf",
                    _T["tf2_msgs/msg/TFMessage"](
                        transforms=[place, _optical(stamp, f"{name}_link")]
                    ),
                ),
            ]
        return out

    def encode(self, record):
        """``[(topic, stamp_ns, cdr_bytes), ...]`` for one ``FrameRecord``."""
        ns = round(record.sim_time * 1e9)
        stamp = _stamp(ns)
        ser, T, g = self._ser, _T, self.geometry
        cam_header = _Header(stamp=stamp, frame_id=_optical_frame("camera_link"))
        odom_header = _Header(stamp=stamp, frame_id="odom")
        out = [
            ("/clock", T["rosgraph_msgs/msg/Clock"](clock=stamp)),
            ("/camera/image_raw", self._image(cam_header, record.camera_rgb)),
            (
                "/camera/camera_info",
                T["sensor_msgs/msg/CameraInfo"](header=cam_header, **self._camera_info),
            ),
        ]
        r = record.result
        if r.filtered is not None:
            out.append(
                (
                    "/fpga/filtered/image",
                    self._image(cam_header, np.take(_RGB444_LUT, r.filtered, axis=0)),
                )
            )
        for topic, value, cls in (
            ("/fpga/found", r.found, "Bool"),
            ("/fpga/proximity", r.proximity, "UInt8"),
            ("/fpga/centroid_x", r.centroid_x, "UInt16"),
            ("/fpga/centroid_leds", r.centroid_leds, "UInt8"),
        ):
            if value is not None:
                out.append(
                    (
                        topic,
                        T[f"std_msgs/msg/{cls}"](data=bool(value) if cls == "Bool" else int(value)),
                    )
                )
        for name, value in (getattr(record, "design_extra", None) or {}).items():
            if value is not None and not math.isnan(value):  # NaN: no value at this frame
                out.append((extra_topic(name), T[EXTRA_TYPE](data=int(value))))
        if r.motor_left is not None and r.motor_right is not None:
            left, right = int(r.motor_left), int(r.motor_right)
            out.append(
                (
                    "/fpga/wheel_dps",
                    T["std_msgs/msg/Int16MultiArray"](
                        layout=self._dps_layout, data=np.array([left, right], np.int16)
                    ),
                )
            )
            v, w = dps_to_twist(left, right, g.wheel_radius, g.wheel_separation)
            out.append(
                (
                    "/cmd_vel",
                    _Twist(linear=_Vector3(x=v, y=0.0, z=0.0), angular=_Vector3(x=0.0, y=0.0, z=w)),
                )
            )
        pose = _Pose(
            position=_Point(x=float(record.robot_x), y=float(record.robot_y), z=0.0),
            orientation=_yaw(float(record.robot_heading)),
        )
        out.append(
            (
                "/odom",
                T["nav_msgs/msg/Odometry"](
                    header=odom_header,
                    child_frame_id="base_link",
                    pose=T["geometry_msgs/msg/PoseWithCovariance"](
                        pose=pose, covariance=self._covariance
                    ),
                    twist=T["geometry_msgs/msg/TwistWithCovariance"](
                        twist=_Twist(
                            linear=_Vector3(x=float(record.robot_v), y=0.0, z=0.0),
                            angular=_Vector3(x=0.0, y=0.0, z=float(record.robot_w)),
                        ),
                        covariance=self._covariance,
                    ),
                ),
            )
        )
        Transform, Stamped = (
            T["geometry_msgs/msg/Transform"],
            T["geometry_msgs/msg/TransformStamped"],
        )
        out.append(
            (
                "/tf",
                T["tf2_msgs/msg/TFMessage"](
                    transforms=[
                        Stamped(
                            header=odom_header,
                            child_frame_id="base_link",
                            transform=Transform(
                                translation=_Vector3(x=pose.position.x, y=pose.position.y, z=0.0),
                                rotation=pose.orientation,
                            ),
                        ),
                        Stamped(
                            header=_Header(stamp=stamp, frame_id="base_link"),
                            child_frame_id="camera_link",
                            transform=self._mount,
                        ),
                        _optical(stamp, "camera_link"),
                    ]
                ),
            )
        )
        out.append(("/people", self._people(odom_header, record.people)))
        out += self._further_cameras(record)
        types = self.topic_types
        return [(topic, ns, ser(msg, types.get(topic) or topic_type(topic))) for topic, msg in out]

    def _people(self, header, people):
        Marker = _T["visualization_msgs/msg/Marker"]
        markers = []
        for i, p in enumerate(people):
            rgba = _TARGET_RGBA if p.is_target else _PERSON_RGBA
            markers.append(
                Marker(
                    header=header,
                    ns="people",
                    id=i,
                    type=Marker.CYLINDER,
                    action=Marker.ADD,
                    pose=_Pose(
                        position=_Point(x=float(p.x), y=float(p.y), z=_PERSON_HEIGHT / 2),
                        orientation=_yaw(0.0),
                    ),
                    scale=_Vector3(x=2 * p.radius, y=2 * p.radius, z=_PERSON_HEIGHT),
                    color=_ColorRGBA(r=rgba[0], g=rgba[1], b=rgba[2], a=rgba[3]),
                    lifetime=_Duration(sec=0, nanosec=0),
                    frame_locked=False,
                    points=[],
                    colors=[],
                    texture_resource="",
                    texture=_T["sensor_msgs/msg/CompressedImage"](
                        header=header, format="", data=np.zeros(0, np.uint8)
                    ),
                    uv_coordinates=[],
                    text=p.name,
                    mesh_resource="",
                    mesh_file=_T["visualization_msgs/msg/MeshFile"](
                        filename="", data=np.zeros(0, np.uint8)
                    ),
                    mesh_use_embedded_materials=False,
                )
            )
        return _T["visualization_msgs/msg/MarkerArray"](markers=markers)
