"""The recorder writes what it is given: a short synthetic run saved to .rrd and read back.

Frames are built here with known values (no dependence on the closed loop); the file is read
back with ``rerun.chunk.RrdReader`` (through ``viz.readback``) and compared with them.
"""

import dataclasses
import math
import os

import cv2
import numpy as np
import pytest
import rerun.blueprint as rrb

from fpga_robotics.cli.readback import main as readback_main
from fpga_robotics.sim.backends.base import FrameResult
from fpga_robotics.sim.camera.frames import rgb444_to_rgb888
from fpga_robotics.sim.camera.scene import CameraPose
from fpga_robotics.sim.records import FrameRecord, PersonState, WorldMap
from fpga_robotics.viz import ViewerError, open_recorder
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.leds import CELL, GAP, cell_centre
from fpga_robotics.viz.readback import images, read_rrd

PER_FRAME = [
    P.LEDS_PROXIMITY,
    P.LEDS_CENTROID,
    P.DESIGN_TRACKING,
    P.DESIGN_CENTROID_X,
    P.MOTORS_DPS,
    P.TWIST_V,
    P.TWIST_W,
    P.TARGET_DISTANCE,
    P.MAP_ROBOT,
    P.MAP_FOV,
    P.MAP_PEOPLE,
    P.TRAIL_ROBOT,
    P.TRAIL_TARGET,
]

WORLD = WorldMap(
    walls=[((0.0, 0.0), (6.0, 0.0)), ((6.0, 0.0), (6.0, 4.0))],
    obstacles=[[(1.0, 1.0), (2.0, 1.0), (2.0, 1.5)]],
    obstacle_colors=[(120, 80, 40)],
    bounds=(0.0, 0.0, 6.0, 4.0),
)


def smooth_image(h, w, seed):
    """A smooth RGB image (JPEG keeps it close), different per seed."""
    y, x = np.mgrid[0:h, 0:w]
    img = np.stack(
        [
            128 + 100 * np.sin(x / 7 + seed),
            128 + 100 * np.cos(y / 5 + seed),
            (x + y + 10 * seed) % 256,
        ],
        axis=-1,
    )
    return img.clip(0, 255).astype(np.uint8)


def make_frames(n, w=32, h=24, seed=0):
    rng = np.random.default_rng(seed)
    frames = []
    for i in range(n):
        filtered = rng.integers(0, 4096, (h, w)).astype(np.uint16)
        filtered[rng.random((h, w)) < 0.7] = 0
        result = FrameResult(
            filtered=filtered,
            found=bool(i % 3),
            proximity=i % 8,
            centroid_x=(7 * i) % w,
            centroid_leds=(37 * i + 5) % 256,
            motor_left=-300 + 47 * i,
            motor_right=250 - 31 * i,
            cycles=1000 + i,
        )
        events = []
        if i == 2:
            events = ["target found"]
        if i == 5:
            events = ["collision with wall", "colour select changed to green"]
        people = [
            PersonState("target", 3.0 + 0.1 * i, 2.0 - 0.05 * i, 0.25, True),
            PersonState("walker", 4.5, 0.5 + 0.1 * i, 0.2, False),
        ]
        frames.append(
            FrameRecord(
                frame=i,
                sim_time=0.05 * i,
                camera_rgb=rng.integers(0, 256, (h, w, 3), dtype=np.uint8),
                color_sel=4,
                result=result,
                robot_x=1.0 + 0.02 * i,
                robot_y=2.0 + 0.01 * i,
                robot_heading=0.3 * i,
                robot_v=0.1 * i,
                robot_w=-0.05 * i,
                cmd_v=0.11 * i,
                cmd_w=-0.06 * i,
                camera_hfov=1.0,
                people=people,
                target_distance=None if i == 4 else 2.0 + 0.1 * i,
                target_in_view=True,
                events=events,
            )
        )
    return frames


def record(path, frames, **kwargs):
    with open_recorder(f"save:{path}", default_path=str(path), **kwargs) as rec:
        rec.log_world_map(WORLD)
        for f in frames:
            rec.log_frame(f)
    return rec


def single(values):
    """The one instance of each row."""
    assert all(len(v) == 1 for v in values)
    return [v[0] for v in values]


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    path = tmp_path_factory.mktemp("viz") / "run.rrd"
    frames = make_frames(12)
    rec = record(path, frames)
    return path, frames, rec, read_rrd(str(path))


def test_every_entity_is_there_once_per_frame(saved):
    _, frames, rec, data = saved
    n = len(frames)
    for entity in [P.CAMERA_RAW, P.CAMERA_FILTERED, *PER_FRAME]:
        assert entity in data.entities, entity
        expected = n - 1 if entity == P.TARGET_DISTANCE else n  # frame 4 has no distance
        assert len(data.entities[entity]) == expected, entity
    assert data.entities[P.MOTORS_DPS].frames == list(range(n))
    assert data.entities[P.MOTORS_DPS].sim_time_ns == [round(0.05 * i * 1e9) for i in range(n)]
    assert data.blueprints == 1
    assert rec.frames_logged == n and rec.images_logged == n
    assert "LineStrips2D:strips" in data.static[P.MAP_WALLS]
    # Furniture is on the timeline (a piece may leave the room): drawn from frame 0 on.
    assert data.entities[P.MAP_FURNITURE].frames == [0]


def test_small_frames_are_logged_as_png_and_exact(saved):
    _, frames, _, data = saved
    for path in (P.CAMERA_RAW, P.CAMERA_FILTERED):
        values = data.entities[path].values
        assert "Image:buffer" not in values
        assert single(values["EncodedImage:media_type"]) == ["image/png"] * len(frames)
        for blob in single(values["EncodedImage:blob"]):
            assert bytes(blob[:8]) == b"\x89PNG\r\n\x1a\n"  # the PNG signature
    raw, filt = images(data, P.CAMERA_RAW), images(data, P.CAMERA_FILTERED)
    assert sorted(raw) == sorted(filt) == list(range(len(frames)))
    for i, f in enumerate(frames):
        # The camera frame as the design receives it: each channel's top four bits.
        np.testing.assert_array_equal(raw[i], f.camera_rgb & 0xF0)
        np.testing.assert_array_equal(filt[i], rgb444_to_rgb888(f.result.filtered))


def test_jpeg_quality_0_logs_raw_images(tmp_path):
    frames = make_frames(3)
    data = read_rrd(str(record(tmp_path / "raw.rrd", frames, jpeg_quality=0).path))
    values = data.entities[P.CAMERA_RAW].values
    assert "EncodedImage:blob" not in values
    fmt = single(values["Image:format"])[2]
    assert (fmt["width"], fmt["height"]) == (32, 24)
    np.testing.assert_array_equal(
        single(values["Image:buffer"])[2].reshape(24, 32, 3), frames[2].camera_rgb & 0xF0
    )
    np.testing.assert_array_equal(
        images(data, P.CAMERA_FILTERED)[1], rgb444_to_rgb888(frames[1].result.filtered)
    )


def led_states(buffer, fmt, n):
    img = buffer.reshape(fmt["height"], fmt["width"], 3)
    assert img.shape == (CELL + 2 * GAP, n * (CELL + GAP) + GAP, 3)
    return [int(img[cell_centre(i)].max()) > 100 for i in range(n)]


def test_leds_show_proximity_bar_and_centroid_bits(saved):
    _, frames, _, data = saved
    prox = data.entities[P.LEDS_PROXIMITY]
    cent = data.entities[P.LEDS_CENTROID]
    pfmt = data.static[P.LEDS_PROXIMITY]["Image:format"][0]
    cfmt = data.static[P.LEDS_CENTROID]["Image:format"][0]
    for i, f in enumerate(frames):
        level = f.result.proximity
        assert led_states(single(prox.values["Image:buffer"])[i], pfmt, 7) == [
            k < level for k in range(7)
        ]
        bits = f.result.centroid_leds
        assert led_states(single(cent.values["Image:buffer"])[i], cfmt, 8) == [
            bool(bits >> k & 1) for k in range(8)
        ]


def test_series_equal_what_was_given(saved):
    _, frames, _, data = saved
    e = data.entities
    assert e[P.DESIGN_TRACKING].values["Scalars:scalars"] == [
        [float(f.result.found), float(f.result.proximity)] for f in frames
    ]
    assert e[P.DESIGN_CENTROID_X].values["Scalars:scalars"] == [
        [float(f.result.centroid_x)] for f in frames
    ]
    assert e[P.MOTORS_DPS].values["Scalars:scalars"] == [
        [float(f.result.motor_left), float(f.result.motor_right)] for f in frames
    ]
    assert e[P.TWIST_V].values["Scalars:scalars"] == [[f.cmd_v, f.robot_v] for f in frames]
    assert e[P.TWIST_W].values["Scalars:scalars"] == [[f.cmd_w, f.robot_w] for f in frames]
    with_distance = [f for f in frames if f.target_distance is not None]
    assert e[P.TARGET_DISTANCE].frames == [f.frame for f in with_distance]
    assert e[P.TARGET_DISTANCE].values["Scalars:scalars"] == [
        [f.target_distance] for f in with_distance
    ]
    names = data.static[P.MOTORS_DPS]["SeriesLines:names"]
    assert names == ["left", "right"]


def test_events_are_text_at_their_frame(saved):
    data = saved[3]
    ev = data.entities[P.EVENTS]
    got = [
        (frame, text, level)
        for frame, texts, levels in zip(
            ev.frames, ev.values["TextLog:text"], ev.values["TextLog:level"], strict=True
        )
        for text, level in zip(texts, levels, strict=True)
    ]
    assert sorted(got) == sorted(
        [
            (2, "target found", "INFO"),
            (5, "collision with wall", "WARN"),
            (5, "colour select changed to green", "INFO"),
        ]
    )


def test_map_field_of_view_is_drawn_from_the_camera_on_its_mount(tmp_path):
    # A camera 0.1 m ahead of the centre, yawed 30 deg left: the wedge's apex is the camera,
    # its rays at 0 and 60 deg (the body heads at 0 deg).
    frames = make_frames(2)
    frames[1] = dataclasses.replace(
        frames[1], robot_heading=0.0, camera_pose=CameraPose(1.12, 2.01, math.radians(30))
    )
    record(tmp_path / "run.rrd", frames)
    data = read_rrd(str(tmp_path / "run.rrd"))
    left, apex, right = single(data.entities[P.MAP_FOV].values["LineStrips2D:strips"])[1]
    np.testing.assert_allclose(apex, [1.12, -2.01], atol=1e-6)
    ang_left = math.atan2(-(left[1] - apex[1]), left[0] - apex[0])
    ang_right = math.atan2(-(right[1] - apex[1]), right[0] - apex[0])
    assert ang_left == pytest.approx(math.radians(30) + 0.5, abs=1e-5)
    assert ang_right == pytest.approx(math.radians(30) - 0.5, abs=1e-5)
    origin = single(data.entities[P.MAP_ROBOT].values["Arrows2D:origins"])[1]
    np.testing.assert_allclose(origin, [1.02, -2.01], atol=1e-5)  # the body stays put


def test_map_robot_people_and_trails(saved):
    _, frames, _, data = saved
    e = data.entities
    # The map is drawn with y flipped (viewer y points down).
    reach = 0.25 * 6.0
    for i, f in enumerate(frames):
        origin = single(e[P.MAP_ROBOT].values["Arrows2D:origins"])[i]
        vector = single(e[P.MAP_ROBOT].values["Arrows2D:vectors"])[i]
        np.testing.assert_allclose(origin, [f.robot_x, -f.robot_y], atol=1e-5)
        h = f.robot_heading
        np.testing.assert_allclose(
            vector, [0.4 * reach * math.cos(h), -0.4 * reach * math.sin(h)], atol=1e-5
        )
        left, apex, right = single(e[P.MAP_FOV].values["LineStrips2D:strips"])[i]
        np.testing.assert_allclose(apex, origin, atol=1e-6)
        # The left ray is half the field of view counter-clockwise of the heading (in the world).
        ang_left = math.atan2(-(left[1] - apex[1]), left[0] - apex[0])
        ang_right = math.atan2(-(right[1] - apex[1]), right[0] - apex[0])
        assert math.isclose(math.remainder(ang_left - h, math.tau), 0.5, abs_tol=1e-5)
        assert math.isclose(math.remainder(ang_right - h, math.tau), -0.5, abs_tol=1e-5)
        people = e[P.MAP_PEOPLE].values
        np.testing.assert_allclose(
            people["Points2D:positions"][i], [[p.x, -p.y] for p in f.people], atol=1e-5
        )
        np.testing.assert_allclose(people["Points2D:radii"][i], [p.radius for p in f.people])
        assert people["Points2D:labels"][i] == [p.name for p in f.people]
    # Trails chain: each segment starts where the previous one ended.
    for entity, where in ((P.TRAIL_ROBOT, "robot"), (P.TRAIL_TARGET, "target")):
        segs = single(e[entity].values["LineStrips2D:strips"])
        for i, f in enumerate(frames):
            if where == "robot":
                now = [f.robot_x, -f.robot_y]
            else:
                now = [f.people[0].x, -f.people[0].y]
            np.testing.assert_allclose(segs[i][1], now, atol=1e-5)
            if i:
                np.testing.assert_allclose(segs[i][0], segs[i - 1][1], atol=1e-6)


def test_log_every_and_jpeg(tmp_path):
    path = tmp_path / "jpeg.rrd"
    frames = make_frames(10, w=64, h=48)
    frames = [
        FrameRecord(**{**f.__dict__, "camera_rgb": smooth_image(48, 64, i)})
        for i, f in enumerate(frames)
    ]
    rec = record(path, frames, log_every=3, jpeg_quality=90)
    data = read_rrd(str(path))
    raw = data.entities[P.CAMERA_RAW]
    assert raw.frames == [0, 3, 6, 9] and rec.images_logged == 4
    assert len(data.entities[P.MOTORS_DPS]) == 10  # series are not decimated
    assert single(raw.values["EncodedImage:media_type"]) == ["image/jpeg"] * 4
    for k, blob in enumerate(single(raw.values["EncodedImage:blob"])):
        bgr = cv2.imdecode(blob, cv2.IMREAD_COLOR)
        assert bgr.shape == (48, 64, 3)
        rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
        original = frames[3 * k].camera_rgb & 0xF0  # the JPEG of what the design saw
        assert np.abs(rgb.astype(int) - original).mean() < 4.0  # the same picture
    filt = single(data.entities[P.CAMERA_FILTERED].values["EncodedImage:blob"])
    assert cv2.imdecode(filt[0], cv2.IMREAD_COLOR).shape == (48, 64, 3)


def test_auto_compression_depends_on_frame_size(tmp_path):
    big = make_frames(2, w=192, h=144)
    data = read_rrd(str(record(tmp_path / "big.rrd", big).path))
    raw = data.entities[P.CAMERA_RAW].values
    assert "EncodedImage:blob" in raw and "Image:buffer" not in raw
    assert cv2.imdecode(raw["EncodedImage:blob"][0][0], cv2.IMREAD_COLOR).shape == (144, 192, 3)
    # jpeg_quality=0: raw whatever the size.
    data = read_rrd(str(record(tmp_path / "raw.rrd", big, jpeg_quality=0).path))
    buf = data.entities[P.CAMERA_RAW].values["Image:buffer"][1][0]
    np.testing.assert_array_equal(buf.reshape(144, 192, 3), big[1].camera_rgb & 0xF0)


def test_file_appears_only_when_closed(tmp_path):
    path = tmp_path / "sub" / "atomic.rrd"
    rec = open_recorder(f"save:{path}", default_path=str(path))
    for f in make_frames(3):
        rec.log_frame(f)
    assert not path.exists()  # being written under a temporary name
    msg = rec.close()
    assert path.exists()
    assert os.listdir(path.parent) == ["atomic.rrd"]  # no temporary file left behind
    assert str(path) in msg and f"rerun {path}" in msg and "3 frames" in msg
    assert rec.close() == msg  # closing twice is harmless
    with pytest.raises(RuntimeError, match="closed"):
        rec.log_frame(make_frames(1)[0])


def test_a_path_below_a_file_is_a_viewer_error(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(ViewerError, match="is not a folder"):
        open_recorder(f"save:{blocker}/run.rrd", default_path=str(tmp_path / "d.rrd"))


def test_context_manager_saves_on_error(tmp_path):
    path = tmp_path / "crash.rrd"
    with (
        pytest.raises(RuntimeError, match="boom"),
        open_recorder(f"save:{path}", default_path=str(path)) as rec,
    ):
        for f in make_frames(4):
            rec.log_frame(f)
        raise RuntimeError("boom")
    data = read_rrd(str(path))
    assert data.entities[P.MOTORS_DPS].frames == [0, 1, 2, 3]


def test_two_recorders_in_one_process_do_not_mix(tmp_path):
    a, b = tmp_path / "a.rrd", tmp_path / "b.rrd"
    fa, fb = make_frames(5, seed=1), make_frames(7, seed=2)
    ra = open_recorder(f"save:{a}", default_path=str(a), camera="rgb888")
    rb = open_recorder(f"save:{b}", default_path=str(b))
    for i in range(7):
        if i < 5:
            ra.log_frame(fa[i])
        rb.log_frame(fb[i])
    ra.close()
    rb.close()
    da, db = read_rrd(str(a)), read_rrd(str(b))
    assert da.entities[P.CAMERA_RAW].frames == list(range(5))
    assert db.entities[P.CAMERA_RAW].frames == list(range(7))
    # Each keeps its own camera format: a the full render, b what the design received.
    np.testing.assert_array_equal(images(da, P.CAMERA_RAW)[4], fa[4].camera_rgb)
    np.testing.assert_array_equal(images(db, P.CAMERA_RAW)[6], fb[6].camera_rgb & 0xF0)


def test_off_records_nothing(tmp_path):
    path = tmp_path / "never.rrd"
    rec = open_recorder("off", default_path=str(path))
    rec.log_world_map(WORLD)
    for f in make_frames(2):
        rec.log_frame(f)
    assert "nothing was recorded" in rec.close()
    assert not path.exists()


def test_readback_summary(saved, capsys):
    path = saved[0]
    assert readback_main([str(path)]) == 0
    out = capsys.readouterr().out
    assert "12 frames" in out and "blueprints: 1" in out
    assert f"{P.MOTORS_DPS:22s}     12 rows\n" in out
    assert f"{P.CAMERA_RAW:22s}     12 rows, PNG " in out
    # Raw 32x24 RGB frames: 2304 bytes each.
    raw = record(saved[0].with_name("raw.rrd"), make_frames(3), jpeg_quality=0).path
    assert readback_main([str(raw)]) == 0
    out = capsys.readouterr().out
    assert f"{P.CAMERA_RAW:22s}      3 rows, raw 2.3 kB each\n" in out
    with pytest.raises(SystemExit) as info:  # no file named: one line, exit 2
        readback_main([])
    assert info.value.code == 2
    assert capsys.readouterr().err.startswith("fpga-robotics readback: error: ")


def chunk_rows(path, entity):
    """The row count of each chunk of ``entity`` in the file, in file order."""
    from rerun.chunk import RrdReader

    return [
        c.to_record_batch().num_rows
        for c in RrdReader(str(path)).stream()
        if c.entity_path.lstrip("/") == entity and not c.is_static
    ]


def test_a_file_alone_is_chunked_by_frames_not_by_time(tmp_path, monkeypatch):
    # The buffer's clock jumps a second a call: the live modes' 0.1 s limit would send
    # every frame.
    import types

    from fpga_robotics.viz import columns

    ticks = iter(range(10**6))
    monkeypatch.setattr(
        columns, "time", types.SimpleNamespace(monotonic=lambda: float(next(ticks)))
    )
    frames = make_frames(300)
    path = record(tmp_path / "file.rrd", frames).path
    assert chunk_rows(path, P.MOTORS_DPS) == [128, 128, 44]
    assert chunk_rows(path, P.CAMERA_RAW) == [128, 128, 44]


@pytest.mark.parametrize("where", ["_add_map", "_send_blueprint"])
def test_a_frame_cut_short_by_ctrl_c_is_neither_kept_nor_counted(tmp_path, monkeypatch, where):
    """Ctrl-C in the middle of logging frame 3 (after its images and motors): the file
    holds frames 0..2 and the closing line counts exactly those."""
    path = tmp_path / "cut.rrd"
    frames = make_frames(4)
    with (
        pytest.raises(KeyboardInterrupt),
        open_recorder(f"save:{path}", default_path=str(path)) as rec,
    ):
        rec.log_world_map(WORLD)  # a closed-loop run's: the map is drawn every frame
        for f in frames[:3]:
            rec.log_frame(f)
        original = getattr(rec, where)

        def interrupted(*args, **kwargs):
            original(*args, **kwargs)
            raise KeyboardInterrupt

        monkeypatch.setattr(rec, where, interrupted)
        rec._layout_stale = True  # so that the blueprint is sent again for frame 3
        rec.log_frame(frames[3])
    data = read_rrd(str(path))
    for entity in (P.CAMERA_RAW, P.MOTORS_DPS, P.TWIST_V):
        assert data.entities[entity].frames == [0, 1, 2], entity
    assert rec.frames_logged == 3 and rec.images_logged == 3
    assert "saved 3 frames (3 with images)" in rec.close()


def _view_names(container):
    """The names of the views in a blueprint container, depth first."""
    names = []
    for item in container.contents:
        if isinstance(item, rrb.Container):
            names += _view_names(item)
        else:
            names.append(item.name)
    return names


@pytest.mark.parametrize(
    "camera_input, title",
    [
        (True, "Camera (RGB444, as the design receives it)"),
        (False, "Camera (filming the run; not a design input)"),
    ],
)
def test_the_camera_view_says_whether_the_design_takes_its_frames(
    tmp_path, monkeypatch, camera_input, title
):
    """A design without frame outputs may still take the camera (a camera design of one's
    own) or not (corridor_follow, follow_line: it films the run for the viewer only)."""
    import fpga_robotics.viz.recorder as recorder_module

    layouts = []
    original = recorder_module.default_blueprint

    def capture(*args, **kwargs):
        layouts.append(original(*args, **kwargs))
        return layouts[-1]

    monkeypatch.setattr(recorder_module, "default_blueprint", capture)
    no_outputs = FrameResult(
        found=None,
        proximity=None,
        centroid_x=None,
        centroid_leds=None,
        motor_left=10,
        motor_right=10,
        filtered=None,
        cycles=None,
    )
    frames = [
        FrameRecord(**{**f.__dict__, "result": no_outputs, "camera_input": camera_input})
        for f in make_frames(2)
    ]
    record(tmp_path / "c.rrd", frames)
    names = _view_names(layouts[-1].root_container)
    assert title in names
    assert "Filtered (design output)" not in names
