"""The world in 3D in the recording (viz.world3d): a short closed-loop run saved and read back;
the room, the furniture, the robot, the people and the camera's pinhole and pose are where
the run put them."""

import math

import numpy as np
import pytest
from rerun.chunk import RrdReader

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.world.robots import ROBOT_MODELS
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz.readback import read_rrd
from fpga_robotics.viz.world3d import CAMERA, camera_rotation, world3d_view


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    path = tmp_path_factory.mktemp("w3d") / "divider.rrd"
    scenario = load_scenario("divider", ["sim.duration=0.5"])
    with open_recorder(f"save:{path}", default_path=str(path)) as rec:
        result = run_scenario(scenario, backend="model", recorder=rec)
    return scenario, result, read_rrd(str(path))


def test_the_room_and_the_divider_are_boxes_of_their_size(recorded):
    _scenario, _, data = recorded
    room = data.static["world3d/room"]
    halves = sorted(tuple(round(v, 4) for v in h) for h in room["Boxes3D:half_sizes"])
    # 8 x 6 m room, 2.5 m high: two walls 4 m and two 3 m half long, 1.25 m half high.
    assert halves == [(3.0, 0.025, 1.25)] * 2 + [(4.0, 0.025, 1.25)] * 2
    furniture = data.entities["world3d/furniture"]
    assert furniture.frames == [0]  # on the timeline: a piece may leave the room
    (centers,) = furniture.values["Boxes3D:centers"]
    assert len(centers) == 2  # the divider's two faces
    for c in centers:
        assert c[2] == pytest.approx(1.8 / 2)  # its height, 1.8 m
        assert abs(c[0] - 7.3) < 0.03 and c[1] == pytest.approx(3.0)


def test_the_camera_pinhole_and_pose_follow_the_robot(recorded):
    scenario, result, data = recorded
    pinhole = data.static[CAMERA]
    f = 80 / math.tan(scenario.camera.hfov / 2)
    # image_from_camera, column-major: [f, 0, 0, 0, f, 0, cx, cy, 1].
    k = pinhole["Pinhole:image_from_camera"][0]
    assert k[0] == pytest.approx(f, rel=1e-5) and k[4] == pytest.approx(f, rel=1e-5)
    assert (k[6], k[7]) == pytest.approx((80.0, 60.0))
    rows = data.entities[CAMERA]
    traj = result.trajectory
    n = len(traj["t"])
    assert rows.frames == list(range(n))
    spec = ROBOT_MODELS["turtlebot2"]  # the divider's robot: its camera mount
    forward = spec.camera_forward
    for i in (0, n - 1):
        x, y, h = traj["x"][i], traj["y"][i], traj["heading"][i]
        tx, ty, tz = rows.values["Transform3D:translation"][i][0]
        assert (tx, ty, tz) == pytest.approx(
            (x + forward * math.cos(h), y + forward * math.sin(h), spec.camera_height), abs=1e-5
        )
        m = np.array(rows.values["Transform3D:mat3x3"][i][0]).reshape(3, 3).T  # column-major
        # The camera's forward axis (its third column) is the robot's heading.
        assert m[:, 2] == pytest.approx([math.cos(h), math.sin(h), 0.0], abs=1e-5)


def test_people_and_robot_are_drawn_each_frame(recorded):
    _, result, data = recorded
    n = len(result.trajectory["t"])
    heads = data.entities["world3d/people/heads"]
    robot = data.entities["world3d/robot"]
    assert len(heads) == len(robot) == n
    # The map's layout, then the one with the 3D view beside the map, sent once.
    assert data.blueprints == 2
    (head,) = heads.values["Points3D:positions"][-1]
    assert head[2] == pytest.approx(1.63)  # a 1.75 m person's head centre
    (centre,) = robot.values["Cylinders3D:centers"][-1]
    assert centre[:2] == pytest.approx(
        (result.trajectory["x"][-1], result.trajectory["y"][-1]), abs=1e-5
    )


def test_camera_rotation_maps_the_camera_axes():
    m = camera_rotation(math.pi / 2, 0.1)  # looking along +y, tilted up
    assert m[:, 0] == pytest.approx([1.0, 0.0, 0.0])  # right: +x
    assert m[:, 2] == pytest.approx([0.0, math.cos(0.1), math.sin(0.1)])
    assert m[:, 1] == pytest.approx([0.0, math.sin(0.1), -math.cos(0.1)])  # down
    assert np.linalg.det(m) == pytest.approx(1.0)


def test_a_piece_of_furniture_that_leaves_the_room_leaves_the_3d_view_then(tmp_path):
    """The divider taken away at 0.2 s: drawn in the frames before, gone from frame 6 on, as
    on the map and in the camera's frames."""
    path = tmp_path / "gone.rrd"
    scenario = load_scenario("divider", ["sim.duration=0.4", "room.furniture.0.present_until=0.2"])
    with open_recorder(f"save:{path}", default_path=str(path)) as rec:
        run_scenario(scenario, backend="model", recorder=rec)
    data = read_rrd(str(path))
    assert "world3d/furniture" not in data.static
    furniture = data.entities["world3d/furniture"]
    assert furniture.frames == data.entities["map/furniture"].frames == [0, 6]
    assert len(furniture.values["Boxes3D:centers"][0]) == 2  # the divider's two faces
    assert furniture.values["Clear:is_recursive"][1] == [False]  # none left from frame 6


def _sees_the_floor_over_the_near_wall(eye, bounds, wall_height):
    """Whether the line from ``eye`` to every floor point more than 15% of the room's depth
    inside the near wall (y = ymin, along the whole room) passes above that wall's inner
    face."""
    _, ymin, _, ymax = bounds
    _, ey, ez = eye
    wall = ymin + 0.025  # the wall's inner face (5 cm thick, centred on its line)
    for py in np.linspace(ymin + 0.15 * (ymax - ymin), ymax, 9):
        t = (wall - ey) / (py - ey)  # where the line crosses the wall's face
        if ez * (1 - t) <= wall_height:
            return False
    return True


def _eye(view):
    eye = view.properties["EyeControls3D"]
    return (
        tuple(eye.position.as_arrow_array().to_pylist()[0]),
        tuple(eye.look_target.as_arrow_array().to_pylist()[0]),
    )


@pytest.mark.parametrize(
    "bounds, wall_height",
    [
        ((0.0, 0.0, 3.6, 2.8), 2.5),  # line_track's room: hidden entirely from a low eye
        ((0.0, 0.0, 8.0, 6.0), 2.5),
        ((0.0, 0.0, 2.0, 10.0), 2.5),
        ((0.0, 0.0, 12.0, 3.0), 3.0),
        ((0.0, 0.0, 6.0, 1.0), 2.5),  # corridor's
        ((-1.0, -2.0, 3.0, 1.0), 1.0),
    ],
)
def test_the_3d_views_eye_sees_the_room_over_its_near_wall(bounds, wall_height):
    xmin, ymin, xmax, ymax = bounds
    eye, target = _eye(world3d_view(bounds, wall_height))
    assert eye[1] < ymin and eye[2] > wall_height  # in front of the room, above its wall
    assert target == pytest.approx(((xmin + xmax) / 2, (ymin + ymax) / 2, 0.0))
    assert _sees_the_floor_over_the_near_wall(eye, bounds, wall_height)


def test_a_small_rooms_recording_opens_on_the_room_not_its_wall(tmp_path):
    path = tmp_path / "small.rrd"
    overrides = [
        "sim.duration=0.1",
        "room.width=4.0",
        "room.depth=3.0",
        "room.height=3.0",
        "robot.start=[0.8, 1.5]",
        "people.0.waypoints=[[2.8, 1.5]]",
    ]
    with open_recorder(f"save:{path}", default_path=str(path)) as rec:
        run_scenario(load_scenario("approach", overrides), backend="model", recorder=rec)
    halves = read_rrd(str(path)).static["world3d/room"]["Boxes3D:half_sizes"]
    wall_height = 2 * max(h[2] for h in halves)
    assert wall_height == pytest.approx(3.0)
    reader = RrdReader(str(path))
    eyes = [
        chunk.to_record_batch().column("EyeControls3D:position").to_pylist()[-1][0]
        for store in reader.blueprints()
        for chunk in reader.stream(store=store)
        if chunk.entity_path.endswith("/EyeControls3D")
    ]
    assert eyes  # the layout with the 3D view, sent once its first frame came
    assert _sees_the_floor_over_the_near_wall(eyes[-1], (0.0, 0.0, 4.0, 3.0), wall_height)


def test_a_tape_line_on_the_floor_is_drawn_in_the_3d_view(tmp_path):
    # The map and the camera showed a [[room.lines]] track; the 3D view's floor was bare.
    path = tmp_path / "tape.rrd"
    tape = 'room.lines=[{name="tape", points=[[1.0, 1.5], [3.0, 1.5]], width=0.02, color=[0.05, 0.05, 0.05]}]'
    scenario = load_scenario("divider", ["sim.duration=0.1", tape])
    with open_recorder(f"save:{path}", default_path=str(path)) as rec:
        run_scenario(scenario, backend="model", recorder=rec)
    marks = read_rrd(str(path)).static["world3d/floor/marks"]
    v = np.array(marks["Mesh3D:vertex_positions"])
    triangles = marks["Mesh3D:triangle_indices"]
    # A 2 cm band along the tape (round ends, as the map draws it), just above the floor.
    assert v[:, 2] == pytest.approx(0.002)
    assert (v[:, 0].min(), v[:, 0].max()) == pytest.approx((0.99, 3.01), abs=1e-4)
    assert (v[:, 1].min(), v[:, 1].max()) == pytest.approx((1.49, 1.51), abs=1e-4)

    def cross(o, p, q):  # > 0: q left of the line from o to p
        return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])

    def covered(x, y):
        for tri in triangles:
            a, b, c = (v[k, :2] for k in tri)
            d = [cross(a, b, (x, y)), cross(b, c, (x, y)), cross(c, a, (x, y))]
            if min(d) >= -1e-9 or max(d) <= 1e-9:
                return True
        return False

    assert all(covered(x, y) for x in (1.0, 1.7, 3.0) for y in (1.495, 1.5, 1.505))
    assert not any(covered(x, y) for x, y in ((2.0, 1.52), (2.0, 1.48), (3.02, 1.5)))
    colors = {
        tuple(int(b) for b in int(c).to_bytes(4, "big")) for c in marks["Mesh3D:vertex_colors"]
    }
    assert colors == {(13, 13, 13, 255)}


def test_a_frame_cut_short_by_ctrl_c_leaves_nothing_of_its_3d_world(tmp_path, monkeypatch):
    """Ctrl-C while the 3D world of a frame is computed (after its camera pose and robot
    were drawn, before its people): the 3D entities were logged straight to the stream, so
    the file held that frame in part (camera and robot one frame more than the rest)."""
    from fpga_robotics.viz import world3d

    calls = {"n": 0}
    limbs = world3d._limbs

    def interrupted(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 5:  # a person of frame 2 or later (one or two people a frame)
            raise KeyboardInterrupt
        return limbs(*args, **kwargs)

    monkeypatch.setattr(world3d, "_limbs", interrupted)
    path = tmp_path / "cut.rrd"
    scenario = load_scenario("divider", ["sim.duration=0.5"])
    with (
        pytest.raises(KeyboardInterrupt),
        open_recorder(f"save:{path}", default_path=str(path)) as rec,
    ):
        run_scenario(scenario, backend="model", recorder=rec)
    data = read_rrd(str(path))
    kept = list(range(rec.frames_logged))
    assert 1 <= len(kept) < 15
    for entity in ("camera", "world3d/robot", "world3d/people/bodies", "motors/dps", "camera/raw"):
        assert data.entities[entity].frames == kept, entity
