"""The closed loop with the golden-model backend: following, stopping, searching, timing."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fpga_robotics.checks.summary import TIMING_FIELDS
from fpga_robotics.loop.compressed import TRAJECTORY_FIELDS
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend
from fpga_robotics.sim.world.kinematics import dps_to_twist

CONTACT = 0.177 + 0.2  # TurtleBot2 body radius + person radius, m


def bearing_error(traj):
    """Angle from the robot's heading to the target, wrapped to [-pi, pi)."""
    b = np.arctan2(traj["target_y"] - traj["y"], traj["target_x"] - traj["x"])
    return (b - traj["heading"] + np.pi) % (2 * np.pi) - np.pi


def test_follows_the_walking_person_without_colliding():
    s = load_scenario("follow_person", ["sim.duration=10"])
    r = run_scenario(s, seed=3, backend="model")
    t = r.trajectory
    assert r.summary["frames"] == 300 and len(t["t"]) == 300
    assert r.summary["collisions"]["person"] == 0
    assert t["found"].mean() > 0.95
    # The person walks off to the upper right; the robot turns after them and keeps them
    # near the image centre (the camera sees +-30 degrees).
    late = slice(150, None)
    assert np.abs(bearing_error(t)[late]).max() < math.radians(15)
    assert t["heading"][-1] > math.radians(10)
    assert t["x"][-1] - t["x"][0] > 0.5  # it drove towards them
    assert np.nanmin(t["target_distance"]) > CONTACT + 0.3


def test_stops_short_of_a_standing_person():
    s = load_scenario(
        "follow_person",
        [
            "people.0.waypoints=[[4.0, 3.0]]",
            "robot.start=[2.2, 3.0]",
            "sim.duration=12",
            "people.0.speed_jitter=0.0",
        ],
    )
    r = run_scenario(s, seed=0, backend="model")
    t = r.trajectory
    d = t["target_distance"]
    assert d[0] == pytest.approx(1.8)
    # It closes in, then holds position: the proximity thresholds stop it well short.
    assert 0.9 < d[-1] < 1.6 and d[-1] < d[0] - 0.2
    assert d.min() > CONTACT + 0.4
    last_2s = slice(-60, None)
    assert np.abs(t["x"][last_2s] - t["x"][-1]).max() < 0.03
    assert np.abs(t["v"][last_2s]).mean() < 0.06
    assert r.summary["collisions"] == {"person": 0, "wall": 0, "furniture": 0}
    # The design saw it close: the proximity reached the levels that stop or reverse.
    assert t["proximity"][last_2s].max() >= 5


def test_searches_towards_the_side_it_lost_the_target_and_finds_it_again():
    s = load_scenario("lost_target")
    r = run_scenario(s, seed=0, backend="model")
    texts = [e for _, _, e in r.events]
    lost = texts.index("target lost")
    search = texts.index("search started", lost)
    found_again = texts.index("target found", search)
    assert lost < search < found_again
    frame_of = {i: r.events[i][0] for i in range(len(r.events))}
    k_lost, k_search, k_found = frame_of[lost], frame_of[search], frame_of[found_again]
    # The motor controller holds its last command for lost_frames frames, then searches.
    assert k_search - k_lost == s.params.lost_frames - 1
    t = r.trajectory
    # The person left to the robot's left: it spins left in place (right wheel forward).
    spin = slice(k_search, k_found)
    assert (t["motor_left"][spin] == -s.params.search_dps).all()
    assert (t["motor_right"][spin] == s.params.search_dps).all()
    assert (t["w"][k_search + 20 : k_found] > 0.5).all()
    # And the person really was out of view while it searched, and in view when found.
    assert not t["target_in_view"][k_lost + 5 : k_search].any()
    assert t["target_in_view"][k_found]
    assert r.summary["verdict"] == "pass", r.summary["checks"]


def test_commands_take_effect_after_the_actuation_delay():
    for delay_frames in (0, 1, 3):
        s = load_scenario(
            "lost_target", ["sim.duration=5", f"sim.actuation_delay={delay_frames / 30!r}"]
        )
        r = run_scenario(s, seed=0, backend="model")
        t = r.trajectory
        spec_r, spec_l = 0.035, 0.230  # TurtleBot2
        for k in range(len(t["t"])):
            if k < delay_frames:
                expect = (0.0, 0.0)
            else:
                expect = dps_to_twist(
                    t["motor_left"][k - delay_frames],
                    t["motor_right"][k - delay_frames],
                    spec_r,
                    spec_l,
                )
            assert (t["cmd_v"][k], t["cmd_w"][k]) == pytest.approx(expect, abs=1e-12), (
                delay_frames,
                k,
            )


def test_frames_are_captured_on_the_frame_clock():
    s = load_scenario("follow_person", ["sim.duration=1", "camera.fps=15"])
    r = run_scenario(s, seed=0, backend="model")
    assert r.summary["frames"] == 15
    assert np.allclose(r.trajectory["t"], np.arange(15) / 15)
    assert r.summary["sim_time_s"] == pytest.approx(1.0)


def test_same_seed_same_run_and_a_new_seed_changes_it():
    s = load_scenario("follow_person", ["sim.duration=4"])
    a = run_scenario(s, seed=5, backend="model")
    b = run_scenario(s, seed=5, backend="model")
    c = run_scenario(s, seed=6, backend="model")

    def untimed(summary):
        return {k: v for k, v in summary.items() if k not in TIMING_FIELDS}

    assert untimed(a.summary) == untimed(b.summary)
    assert a.events == b.events
    for name in TRAJECTORY_FIELDS:
        assert np.array_equal(a.trajectory[name], b.trajectory[name], equal_nan=True), name
    # The seed draws the person's speed jitter and the camera noise.
    assert not np.array_equal(a.trajectory["target_x"], c.trajectory["target_x"], equal_nan=True)


def test_a_ready_backend_is_reset_and_reused():
    s = load_scenario("follow_person", ["sim.duration=2"])
    design = ModelBackend(s.params)
    first = run_scenario(s, seed=1, backend=design)
    second = run_scenario(s, seed=1, backend=design)
    assert np.array_equal(first.trajectory["motor_left"], second.trajectory["motor_left"])
    with pytest.raises(ValueError, match="other parameters"):
        run_scenario(s.with_overrides(["design.kp_num=1"]), seed=1, backend=design)


def test_frame_records_carry_events_and_the_colour_select():
    s = load_scenario(
        "follow_person", ["sim.duration=3", 'color.changes=[{at = 1.0, color = "green"}]']
    )
    records = []
    r = run_scenario(s, seed=0, backend="model", on_frame=records.append)
    assert len(records) == r.summary["frames"] == 90
    assert records[0].events == ["target found"] and records[0].color_sel == 0b100
    k = 30  # 1.0 s at 30 fps
    assert "colour select changed to green" in records[k].events
    assert records[k].color_sel == 0b010 and records[k - 1].color_sel == 0b100
    # Nothing in the room is green: the design loses the person on that very frame.
    assert "target lost" in records[k].events and not records[k].result.found
    rec = records[10]
    assert rec.camera_rgb.shape == (120, 160, 3) and rec.camera_rgb.dtype == np.uint8
    assert rec.target_in_view and rec.target_distance == pytest.approx(
        r.trajectory["target_distance"][10]
    )
    assert [p.name for p in rec.people] == ["target"]
    assert (rec.robot_x, rec.robot_y) == (r.trajectory["x"][10], r.trajectory["y"][10])


def test_recorder_gets_the_map_once_and_every_frame():
    class Recorder:
        def __init__(self):
            self.maps, self.frames = [], []

        def log_world_map(self, m):
            self.maps.append(m)

        def log_frame(self, rec):
            self.frames.append(rec.frame)

    rec = Recorder()
    s = load_scenario("divider", ["sim.duration=1"])
    run_scenario(s, seed=0, backend="model", recorder=rec)
    assert len(rec.maps) == 1 and rec.frames == list(range(30))
    assert len(rec.maps[0].obstacles) == 1  # the divider


def test_progress_is_reported_per_frame():
    calls = []
    s = load_scenario("follow_person", ["sim.duration=0.5"])
    run_scenario(s, seed=0, backend="model", progress=lambda d, n: calls.append((d, n)))
    assert calls == [(k, 15) for k in range(1, 16)]


def test_a_looser_colour_filter_takes_the_divider_for_the_person():
    """The paper's debugging story: red-brown wood passes a too-permissive red filter, the
    robot turns towards the divider and lets the person walk out of view."""
    base = load_scenario("divider")
    good = run_scenario(base, seed=0, backend="model")
    loose = run_scenario(base.with_overrides(["design.diff_min=5"]), seed=0, backend="model")
    assert good.summary["target_in_view_fraction"] > 0.95
    assert loose.summary["target_in_view_fraction"] < 0.7
    assert loose.summary["verdict"] == "fail" and good.summary["verdict"] == "pass"


@pytest.mark.slow
def test_a_compiled_backend_drives_the_robot_exactly_as_the_model_does():
    """The compiled design is bit exact, so the whole closed loop must be identical."""
    from fpga_robotics.sim.backends import (
        COMPILED_BACKENDS,
        BackendError,
        available_backends,
        get_backend,
    )

    names = [n for n in COMPILED_BACKENDS if n in available_backends()]
    if not names:
        pytest.skip("no C++ compiler / verilator here: no compiled backend")
    s = load_scenario("lost_target", ["sim.duration=6"])
    try:
        design = get_backend(names[0], s.params)
    except BackendError as exc:
        pytest.skip(f"{names[0]} cannot build here: {exc}")
    with design:
        compiled = run_scenario(s, seed=2, backend=design)
    model = run_scenario(s, seed=2, backend="model")
    assert compiled.summary["backend"] == names[0]
    assert compiled.events == model.events
    for name in TRAJECTORY_FIELDS:
        assert np.array_equal(compiled.trajectory[name], model.trajectory[name], equal_nan=True), (
            name
        )
    assert "search started" in [e for _, _, e in compiled.events]


def test_camera_pose_and_field_of_view_geometry():
    from fpga_robotics.loop.connectors import camera_pose, in_view

    pose = camera_pose((1.0, 2.0, math.pi / 2), height=0.3, forward=0.1, tilt=0.05)
    assert (pose.x, pose.y, pose.height, pose.tilt) == pytest.approx((1.0, 2.1, 0.3, 0.05))
    cam = SimpleNamespace(width=160, height=120, hfov=math.radians(60))
    # Straight ahead, 2 m away: in view. 29 deg off-axis: in; 40 deg: the centre is out but a
    # 0.5 m radius still reaches into the view (asin(0.5/2) = 14.5 deg); behind: out.
    ahead = (pose.x, pose.y + 2.0)
    assert in_view(pose, cam, *ahead, 0.2, 1.75)
    for deg, radius, expect in (
        (29, 0.0, True),
        (31, 0.0, False),
        (40, 0.5, True),
        (40, 0.1, False),
        (180, 0.2, False),
    ):
        a = math.pi / 2 + math.radians(deg)
        p = (pose.x + 2 * math.cos(a), pose.y + 2 * math.sin(a))
        assert in_view(pose, cam, *p, radius, 1.75) is expect, deg
    assert in_view(pose, cam, pose.x, pose.y - 0.1, 0.2, 1.75)  # the camera is inside the body


#: The default camera: 160x120, hfov 1.047 rad, f = 80 / tan(0.5235) = 138.6 px, half the
#: vertical field of view atan(60 / 138.6) = 0.4087 rad.
CAM = SimpleNamespace(width=160, height=120, hfov=1.047)
HALF_VFOV = math.atan(60 / (80 / math.tan(1.047 / 2)))


def _rendered_pixels(pose, distance, bearing, radius, height):
    """The pixels the renderer draws of a red cylinder (blue floor and ceiling, even light)."""
    from fpga_robotics.sim.camera.raster import render
    from fpga_robotics.sim.camera.scene import Band, Cylinder, Lighting, Scene

    x = pose.x + distance * math.cos(pose.heading + bearing)
    y = pose.y + distance * math.sin(pose.heading + bearing)
    person = Cylinder(x=x, y=y, radius=radius, bands=(Band(0.0, height, (1.0, 0.0, 0.0)),))
    blue = (0.0, 0.0, 1.0)
    scene = Scene(
        cylinders=(person,),
        lighting=Lighting(ambient=1.0, intensity=0.0),
        floor_color=blue,
        ceiling_color=blue,
        ceiling_height=10.0,
    )
    image = render(scene, pose, CAM.width, CAM.height, CAM.hfov)
    return int(np.count_nonzero(image[..., 0] > 128))


def test_field_of_view_is_vertical_too():
    from fpga_robotics.loop.connectors import in_view
    from fpga_robotics.sim.camera.scene import CameraPose

    # A person 1.75 m tall, 0.2 m in radius, 1.3 m straight ahead of a camera 0.3 m up: its
    # near side (1.1 m deep) shows the feet atan(-0.3 / 1.1) = -0.2663 rad below the level,
    # the lowest it reaches. Tilted down by more than 0.2663 + 0.4087 = 0.6750 rad the image's
    # top row looks below the feet: nothing of the person is in the image.
    edge = math.atan(0.3 / 1.1) + HALF_VFOV
    for tilt, expect in ((-edge + 0.02, True), (-edge - 0.02, False), (-1.0, False)):
        pose = CameraPose(0.0, 0.0, 0.0, height=0.3, tilt=tilt)
        assert in_view(pose, CAM, 1.3, 0.0, 0.2, 1.75) is expect, tilt
        assert (_rendered_pixels(pose, 1.3, 0.0, 0.2, 1.75) > 0) is expect, tilt
    # Tilted up by 0.6 rad, the image's bottom row looks 0.6 - 0.4087 = 0.1913 rad up: the
    # head's top, 1.45 m above the camera, is at atan(1.45 / 3.8) = 0.3645 rad 4 m away (in)
    # and at atan(1.45 / 9.8) = 0.1469 rad 10 m away (out).
    pose = CameraPose(0.0, 0.0, 0.0, height=0.3, tilt=0.6)
    for distance, expect in ((4.0, True), (10.0, False)):
        assert in_view(pose, CAM, distance, 0.0, 0.2, 1.75) is expect, distance
        assert (_rendered_pixels(pose, distance, 0.0, 0.2, 1.75) > 0) is expect, distance
    # A child 1.0 m tall 2 m ahead of a level camera 2.0 m up (a ceiling camera): the head's
    # top at atan(-1.0 / 1.8) = -0.5071 rad is below the image's bottom row (-0.4087).
    pose = CameraPose(0.0, 0.0, 0.0, height=2.0, tilt=0.0)
    assert not in_view(pose, CAM, 2.0, 0.0, 0.2, 1.0)
    assert in_view(pose, CAM, 2.0, 0.0, 0.2, 1.75)  # a grown-up's head is in


def test_a_person_the_renderer_draws_is_in_view():
    """Wherever the renderer draws a pixel of the person, in_view says so: camera heights
    and tilts, people short and tall, near and far, ahead and at the edge of the view."""
    from fpga_robotics.loop.connectors import in_view
    from fpga_robotics.sim.camera.scene import CameraPose

    for cam_height, tilt in ((0.3, -0.9), (0.3, 0.0), (0.3, 0.6), (1.5, -0.5), (2.2, 0.2)):
        pose = CameraPose(0.0, 0.0, 0.0, height=cam_height, tilt=tilt)
        for distance in (0.5, 1.3, 3.0, 8.0):
            for bearing in (0.0, 0.45, -0.7):
                for height in (0.6, 1.75):
                    drawn = _rendered_pixels(pose, distance, bearing, 0.25, height)
                    if drawn:
                        assert in_view(
                            pose,
                            CAM,
                            distance * math.cos(bearing),
                            distance * math.sin(bearing),
                            0.25,
                            height,
                        )


@pytest.mark.parametrize(
    "name", ["follow_person", "divider", "lighting", "heavy_robot", "lost_target"]
)
def test_every_shipped_scenario_passes_with_the_default_design(name):
    s = load_scenario(name)
    assert s.data["design"] == {}  # the default design
    r = run_scenario(s, backend="model")
    failed = [c["text"] for c in r.summary["checks"] if not c["passed"]]
    assert r.summary["verdict"] == "pass", failed


def test_the_steering_gain_grows_with_the_resolution():
    """``kp_num`` is DPS per pixel of centroid error: at 320x240 a radian of error is twice
    the pixels, so the robot turns twice as hard and keeps up with the person who escapes
    it at 160x120 (lost_target then judges its search n/a: the loss it is meant to test never happens)."""
    low = run_scenario(load_scenario("lost_target", ["sim.duration=6"]), backend="model")
    high = run_scenario(
        load_scenario("lost_target", ["sim.duration=6", 'camera.resolution="320x240"']),
        backend="model",
    )
    assert low.summary["searches"] == 1 and high.summary["searches"] == 0
    assert high.trajectory["found"].all()
    assert np.abs(high.trajectory["w"]).max() > 1.5 * np.abs(low.trajectory["w"][:100]).max()


@pytest.mark.parametrize("robot", ["turtlebot2", "gopigo3"])
def test_camera_mount_defaults_to_the_robots_own(robot):
    # A scenario that leaves the mount unset gets the robot's mount: forward offset, height
    # and tilt each from the robot's spec (three different numbers, so a mix-up shows).
    from fpga_robotics.loop.compressed import ClosedLoop
    from fpga_robotics.sim.world.robots import ROBOT_MODELS

    spec = ROBOT_MODELS[robot]
    s = load_scenario("follow_person", [f'robot.model="{robot}"', "sim.duration=0.1"])
    assert s.camera.mount_forward is None and s.camera.mount_height is None
    loop = ClosedLoop(s, design=ModelBackend(s.params))
    x, y, heading = 1.0, 2.0, math.radians(30)
    pose = loop.camera.pose((x, y, heading))
    assert pose.x == pytest.approx(x + spec.camera_forward * math.cos(heading))
    assert pose.y == pytest.approx(y + spec.camera_forward * math.sin(heading))
    assert pose.height == pytest.approx(spec.camera_height)
    assert pose.tilt == pytest.approx(spec.camera_tilt)
    assert spec.camera_forward != spec.camera_height


def test_camera_mount_from_the_scenario_wins():
    from fpga_robotics.loop.compressed import ClosedLoop

    s = load_scenario(
        "follow_person",
        ["camera.mount_forward=0.25", "camera.mount_height=0.2", "sim.duration=0.1"],
    )
    pose = ClosedLoop(s, design=ModelBackend(s.params)).camera.pose((0.0, 0.0, 0.0))
    assert (pose.x, pose.height) == pytest.approx((0.25, 0.2))


def test_frame_count_is_the_capture_rule_counted_directly():
    # Frame k is captured at step round(k * period / dt) and must fall inside the run: the
    # closed form agrees with counting frame by frame, on awkward ratios too.
    from fpga_robotics.loop.compressed import frame_count

    def counted(steps, period, dt):
        n = 0
        while round(n * period / dt) < steps:
            n += 1
        return n

    rng = np.random.default_rng(7)
    for _ in range(500):
        steps = int(rng.integers(1, 5000))
        period = float(rng.choice([1 / 30, 1 / 15, 1 / 7, 0.001, 0.5, rng.uniform(1e-3, 1)]))
        dt = float(rng.choice([1 / 240, 1 / 200, 0.01, 0.3, rng.uniform(1e-4, 0.1)]))
        assert frame_count(steps, period, dt) == counted(steps, period, dt)
    assert frame_count(240 * 10**6, 1 / 30, 1 / 240) == 30 * 10**6  # long runs: no loop
