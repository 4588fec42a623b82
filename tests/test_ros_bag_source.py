"""``--source bag:PATH[:TOPIC]``: frames written by the test into ROS 2 and ROS 1 bags (raw
rgb8 / bgr8 / yuv422, CompressedImage PNG) give the design the same outputs as the same
frames given straight to the model (issue 16)."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.cli.errors import UsageError, run_cli
from fpga_robotics.cli.run import main as run_main
from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.sources import open_source
from fpga_robotics.sim.camera.synthetic import scenario as synthetic_scenario
from fpga_robotics.sim.models.follow_target import FollowTargetModel

W, H = 80, 60
PERIOD_NS = 50_000_000  # 20 fps, as a camera driver would stamp them
T0_NS = 1_700_000_000_000_000_000  # a real robot's bag starts at its wall-clock time
ROS2 = get_typestore(Stores.ROS2_HUMBLE)
ROS1 = get_typestore(Stores.ROS1_NOETIC)


def frames():
    """A red target sweeping across a noisy background, then an empty-ish frame."""
    return synthetic_scenario("sweep", W, H, n_frames=6, rng=5).frames


def to_uyvy(rgb):
    """RGB to UYVY 4:2:2 by BT.601 (video range), chroma averaged over each pixel pair."""
    f = rgb.astype(float)
    r, g, b = f[..., 0], f[..., 1], f[..., 2]
    y = 16 + 0.257 * r + 0.504 * g + 0.098 * b
    u = 128 - 0.148 * r - 0.291 * g + 0.439 * b
    v = 128 + 0.439 * r - 0.368 * g - 0.071 * b
    u2 = (u[:, 0::2] + u[:, 1::2]) / 2
    v2 = (v[:, 0::2] + v[:, 1::2]) / 2
    out = np.empty((rgb.shape[0], rgb.shape[1], 2))
    out[:, 0::2, 0], out[:, 1::2, 0] = u2, v2
    out[..., 1] = y
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


def image_msg(store, rgb, k, encoding, ros1=False):
    T = store.types
    stamp = T["builtin_interfaces/msg/Time"](
        sec=(T0_NS + k * PERIOD_NS) // 10**9, nanosec=(T0_NS + k * PERIOD_NS) % 10**9
    )
    header = (
        T["std_msgs/msg/Header"](seq=k, stamp=stamp, frame_id="cam")
        if ros1
        else T["std_msgs/msg/Header"](stamp=stamp, frame_id="cam")
    )
    if encoding == "png":
        ok, png = cv2.imencode(".png", cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        assert ok
        return "sensor_msgs/msg/CompressedImage", T["sensor_msgs/msg/CompressedImage"](
            header=header, format="png", data=png.reshape(-1)
        )
    pixels = {"rgb8": rgb, "bgr8": rgb[..., ::-1], "yuv422": to_uyvy(rgb)}[encoding]
    step = pixels.shape[1] * pixels.shape[2]
    return "sensor_msgs/msg/Image", T["sensor_msgs/msg/Image"](
        header=header,
        height=rgb.shape[0],
        width=rgb.shape[1],
        encoding=encoding,
        is_bigendian=0,
        step=step,
        data=np.ascontiguousarray(pixels).reshape(-1),
    )


def write_bag(path, images, encoding, *, ros1=False, topic="/camera/image_raw", extra=()):
    """A bag of ``images`` on ``topic`` (and ``extra`` empty image topics)."""
    store = ROS1 if ros1 else ROS2
    writer = Writer1(path) if ros1 else Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        msgtype = image_msg(store, images[0], 0, encoding, ros1)[0]
        conn = writer.add_connection(topic, msgtype, typestore=store)
        for name in extra:
            writer.add_connection(name, msgtype, typestore=store)
        for k, rgb in enumerate(images):
            _, msg = image_msg(store, rgb, k, encoding, ros1)
            data = store.serialize_ros1(msg, msgtype) if ros1 else store.serialize_cdr(msg, msgtype)
            writer.write(conn, T0_NS + k * PERIOD_NS, data)
    return path


def model_outputs(images):
    model = FollowTargetModel(FollowTargetParams(width=W, height=H))
    out = []
    for rgb in images:
        m = model.process(rgb, 0b100)  # red
        out.append(
            [
                m.tracker.found,
                m.tracker.proximity,
                m.tracker.centroid_x,
                m.motor_left,
                m.motor_right,
            ]
        )
    return out


def run_bag(spec, tmp_path, *extra):
    summary = tmp_path / "s.json"
    code = run_main(
        [
            "--source",
            spec,
            "--backend",
            "model",
            "--resolution",
            f"{W}x{H}",
            "--rerun",
            "off",
            "--quiet",
            "--summary",
            str(summary),
            *extra,
        ]
    )
    assert code == 0
    out = json.loads(summary.read_text())
    return [
        [r["found"], r["proximity"], r["centroid_x"], r["motor_left"], r["motor_right"]]
        for r in out["results"]
    ]


@pytest.mark.parametrize(
    "encoding, ros1",
    [("rgb8", False), ("bgr8", False), ("png", False), ("rgb8", True), ("bgr8", True)],
)
def test_lossless_bags_give_the_models_outputs(encoding, ros1, tmp_path):
    images = frames()
    bag = write_bag(tmp_path / ("b.bag" if ros1 else "b"), images, encoding, ros1=ros1)
    src = open_source(f"bag:{bag}", W, H)
    seen = list(src)
    src.close()
    assert all(np.array_equal(a, b) for a, b in zip(seen, images)) and len(seen) == 6
    expected = model_outputs(images)
    assert run_bag(f"bag:{bag}", tmp_path) == expected
    assert any(e[0] for e in expected) and len({e[2] for e in expected}) > 1  # it tracks


def test_yuv422_is_decoded_as_uyvy(tmp_path):
    images = frames()
    # Pixel pairs of one colour lose nothing to 4:2:2: only rounding is left.
    paired = [np.repeat(f[:, 0::2], 2, axis=1) for f in images]
    bag = write_bag(tmp_path / "p", paired, "yuv422")
    src = open_source(f"bag:{bag}:/camera/image_raw", W, H)
    seen = list(src)
    src.close()
    for a, b in zip(seen, paired):
        assert np.abs(a.astype(int) - b.astype(int)).max() <= 3
    bag = write_bag(tmp_path / "b", images, "yuv422")
    # The design sees exactly what OpenCV's UYVY decoder makes of the bytes.
    decoded = [cv2.cvtColor(to_uyvy(rgb), cv2.COLOR_YUV2RGB_UYVY) for rgb in images]
    assert run_bag(f"bag:{bag}", tmp_path) == model_outputs(decoded)


def test_bag_frames_are_resized_and_keep_the_bags_times(tmp_path):
    big = [cv2.resize(f, (2 * W, 2 * H), interpolation=cv2.INTER_NEAREST) for f in frames()]
    bag = write_bag(tmp_path / "b", big, "rgb8")
    src = open_source(f"bag:{bag}", W, H)
    seen = list(src)
    assert [src.frame_time(k) for k in range(6)] == pytest.approx([0.05 * k for k in range(6)])
    src.close()
    expected = [cv2.resize(f, (W, H), interpolation=cv2.INTER_LINEAR) for f in big]
    assert all(np.array_equal(a, b) for a, b in zip(seen, expected))
    # The bag's .mcap file names the same bag.
    src = open_source(f"bag:{bag}/{bag.name}.mcap:/camera/image_raw", W, H)
    assert sum(1 for _ in src) == 6
    src.close()


def test_bag_in_and_bag_out(tmp_path):
    images = frames()
    bag = write_bag(tmp_path / "in", images, "bgr8")
    run_bag(f"bag:{bag}", tmp_path, "--bag", str(tmp_path / "out"))
    with AnyReader([tmp_path / "out"], default_typestore=ROS2) as reader:
        conns = {c.topic: c for c in reader.connections}
        got = [
            reader.deserialize(raw, c.msgtype)
            for c, _, raw in reader.messages(connections=[conns["/camera/image_raw"]])
        ]
        stamps = [t for _, t, _ in reader.messages(connections=[conns["/fpga/found"]])]
        found = [
            reader.deserialize(raw, c.msgtype).data
            for c, _, raw in reader.messages(connections=[conns["/fpga/found"]])
        ]
    assert [g.data.tobytes() for g in got] == [f.tobytes() for f in images]
    assert stamps == [k * PERIOD_NS for k in range(6)]  # the input's times, from its start
    assert found == [e[0] for e in model_outputs(images)]


def test_bad_bags_are_usage_errors(tmp_path):
    images = frames()
    bag = write_bag(tmp_path / "b", images, "rgb8", extra=("/other/image",))
    with pytest.raises(UsageError, match="no topic /nope"):
        open_source(f"bag:{bag}:/nope", W, H)
    empty = write_bag(
        tmp_path / "e",
        images[:0] or [images[0]],
        "rgb8",
        topic="/unused",
        extra=("/camera/image_raw",),
    )
    with pytest.raises(UsageError, match="has no messages"):
        open_source(f"bag:{empty}", W, H)
    mono16 = tmp_path / "m"
    with Writer2(mono16, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/cam", "sensor_msgs/msg/Image", typestore=ROS2)
        msg = ROS2.types["sensor_msgs/msg/Image"](
            header=ROS2.types["std_msgs/msg/Header"](
                stamp=ROS2.types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=""
            ),
            height=2,
            width=2,
            encoding="32FC1",
            is_bigendian=0,
            step=8,
            data=np.zeros(16, np.uint8),
        )
        writer.write(conn, 1, ROS2.serialize_cdr(msg, "sensor_msgs/msg/Image"))
    with pytest.raises(UsageError, match="encoding '32FC1' is not read"):
        open_source(f"bag:{mono16}", W, H)
    with pytest.raises(UsageError, match="no such bag"):
        open_source(f"bag:{tmp_path / 'missing'}", W, H)
    assert Path(bag).is_dir()


@pytest.mark.parametrize(
    "storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3], ids=["mcap", "db3"]
)
def test_a_bags_file_is_read_alone_not_its_folder(storage, tmp_path):
    images = frames()
    bag = tmp_path / "b"
    with Writer2(bag, version=9, storage_plugin=storage) as writer:
        conn = writer.add_connection("/camera/image_raw", "sensor_msgs/msg/Image", typestore=ROS2)
        for k, rgb in enumerate(images):
            _, msg = image_msg(ROS2, rgb, k, "rgb8")
            writer.write(
                conn, T0_NS + k * PERIOD_NS, ROS2.serialize_cdr(msg, "sensor_msgs/msg/Image")
            )
    (data,) = [f for f in bag.iterdir() if f.name != "metadata.yaml"]
    # Copied out alone (no metadata.yaml beside it), and beside another bag's metadata.
    lone = tmp_path / "lone" / f"robot{data.suffix}"
    lone.parent.mkdir()
    lone.write_bytes(data.read_bytes())
    write_bag(tmp_path / "other", images[:2], "rgb8")
    mixed = tmp_path / "other" / f"mine{data.suffix}"
    mixed.write_bytes(data.read_bytes())
    expected = model_outputs(images)
    assert run_bag(f"bag:{lone}", tmp_path) == expected
    assert run_bag(f"bag:{mixed}", tmp_path) == expected  # 6 frames, not the folder's 2


def test_the_recordings_commanded_twist_is_the_bags_cmd_vel(tmp_path):
    from fpga_robotics.viz.readback import read_rrd  # lazy: rerun, for this test only

    bag = write_bag(tmp_path / "in", frames(), "rgb8")
    recording = tmp_path / "r.rrd"
    run_bag(
        f"bag:{bag}",
        tmp_path,
        "--set",
        "robot.model=gopigo3",
        "--bag",
        str(tmp_path / "out"),
        "--rerun",
        f"save:{recording}",
    )
    with AnyReader([tmp_path / "out"], default_typestore=ROS2) as reader:
        (conn,) = [c for c in reader.connections if c.topic == "/cmd_vel"]
        twists = [reader.deserialize(raw, conn.msgtype) for _, _, raw in reader.messages([conn])]
    entities = read_rrd(str(recording)).entities
    # [commanded, measured] a frame; nothing moves on recorded footage.
    v = [values[0] for values in entities["twist/v"].values["Scalars:scalars"]]
    w = [values[0] for values in entities["twist/w"].values["Scalars:scalars"]]
    assert v == pytest.approx([t.linear.x for t in twists])
    assert w == pytest.approx([t.angular.z for t in twists])
    assert len(v) == 6 and any(x > 0 for x in v)  # the design drives


def test_an_encoding_not_read_after_the_first_image_is_refused_before_anything_is_written(
    tmp_path, capsys
):
    images = frames()
    bag = tmp_path / "mixed"
    with Writer2(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/camera/image_raw", "sensor_msgs/msg/Image", typestore=ROS2)
        for k, rgb in enumerate(images):
            _, msg = image_msg(ROS2, rgb, k, "rgb8")
            if k >= 4:  # the camera driver switched to 16-bit grey
                msg.encoding, msg.step = "mono16", 2 * W
                msg.data = np.zeros(2 * W * H, np.uint8)
            writer.write(
                conn, T0_NS + k * PERIOD_NS, ROS2.serialize_cdr(msg, "sensor_msgs/msg/Image")
            )
    out = tmp_path / "out"
    out.mkdir()
    with pytest.raises(SystemExit) as info:
        run_cli(
            run_main,
            [
                "--source",
                f"bag:{bag}",
                "--backend",
                "model",
                "--resolution",
                f"{W}x{H}",
                "--quiet",
                "--rerun",
                f"save:{out / 'r.rrd'}",
                "--summary",
                str(out / "s.json"),
                "--bag",
                str(out / "b"),
            ],
        )
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert "frame 4: image encoding 'mono16' is not read" in err
    assert "--max-frames 4" in err
    assert list(out.iterdir()) == []  # nothing written
    # The frames before it run.
    assert len(run_bag(f"bag:{bag}", tmp_path, "--max-frames", "4")) == 4


@pytest.mark.parametrize("empty_frame, encoding", [(1, "rgb8"), (0, "bgr8")])
def test_an_image_without_pixels_is_refused_before_anything_is_written(
    empty_frame, encoding, tmp_path, capsys
):
    bag = tmp_path / "zero"
    with Writer2(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/camera/image_raw", "sensor_msgs/msg/Image", typestore=ROS2)
        for k, rgb in enumerate(frames()[:3]):
            _, msg = image_msg(ROS2, rgb, k, encoding)
            if k == empty_frame:  # a driver's 0x0 placeholder for a dropped frame
                msg.height = msg.width = msg.step = 0
                msg.data = np.zeros(0, np.uint8)
            writer.write(
                conn, T0_NS + k * PERIOD_NS, ROS2.serialize_cdr(msg, "sensor_msgs/msg/Image")
            )
    out = tmp_path / "out"
    out.mkdir()
    with pytest.raises(SystemExit) as info:
        run_cli(
            run_main,
            [
                "--source",
                f"bag:{bag}",
                "--backend",
                "model",
                "--resolution",
                f"{W}x{H}",
                "--quiet",
                "--rerun",
                f"save:{out / 'r.rrd'}",
                "--summary",
                str(out / "s.json"),
                "--bag",
                str(out / "b"),
            ],
        )
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert f"frame {empty_frame}: a 0x0 image holds no pixels" in err
    assert "Traceback" not in err
    assert list(out.iterdir()) == []  # nothing written


def test_a_compressed_image_that_does_not_decode_ends_the_run_naming_its_frame(tmp_path, capsys):
    images = frames()
    bag = tmp_path / "damaged"
    with Writer2(bag, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection(
            "/camera/image_raw", "sensor_msgs/msg/CompressedImage", typestore=ROS2
        )
        for k, rgb in enumerate(images):
            msgtype, msg = image_msg(ROS2, rgb, k, "png")
            if k == 3:
                msg.data = msg.data[:40]  # cut off in transfer
            writer.write(conn, T0_NS + k * PERIOD_NS, ROS2.serialize_cdr(msg, msgtype))
    out = tmp_path / "out"
    out.mkdir()
    with pytest.raises(SystemExit) as info:
        run_cli(
            run_main,
            [
                "--source",
                f"bag:{bag}",
                "--backend",
                "model",
                "--resolution",
                f"{W}x{H}",
                "--quiet",
                "--rerun",
                "off",
                "--summary",
                str(out / "s.json"),
                "--bag",
                str(out / "b"),
            ],
        )
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert "frame 3: cannot decode a CompressedImage" in err and "--max-frames 3" in err
    assert list(out.iterdir()) == []  # no bag, no summary of the cut-off run
