"""Further cameras and the pan servo in the closed loop: two cameras see their targets at the
columns the pinhole model gives, the servo slews at its datasheet speed, the turret keeps its
target centred while the body turns (and its seeded bug fails the named check), and the viewer
shows each camera."""

import math
import re
from pathlib import Path

import numpy as np
import pytest
from render3d_scenes import mujoco_missing

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.turret_params import TurretParams
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.viz import open_recorder
from fpga_robotics.viz.cameras import CAMERAS, MAP_CAMERAS
from fpga_robotics.viz.readback import images, read_rrd

#: Two cameras, both 60 degrees wide at 160 px: f = 80 / tan(30 deg) = 138.56 px. The robot
#: (GoPiGo3, its camera 0.08 m ahead of the centre) stands at (1.5, 3.0) facing +x; the red
#: person stands 3 m ahead of the body camera and 0.5 m to its right, the blue one 3 m ahead
#: of the pan camera (servo axis 0.02 m ahead, camera 0.03 m further along the horn) and
#: 1 m to its left.
TWO_CAMERAS = """
[sim]
duration = 0.2
[camera]
resolution = "160x120"
fps = 10.0
hfov = 1.0471975511965976
[design]
top = "turret_tracker"
[room]
width = 8.0
depth = 6.0
[robot]
model = "gopigo3"
start = [1.5, 3.0]
[[robot.actuators]]
kind = "servo"
name = "pan"
forward = 0.02
height = 0.2
[[robot.sensors]]
kind = "camera"
name = "turret"
on = "pan"
forward = 0.03
height = 0.22
fps = 10.0
hfov_deg = 60.0
color = "blue"
target = "blue"
ports = { pixels = "turret_pixels", color_sel = "turret_color_sel" }
[[people]]
name = "red"
target = true
shirt_color = [0.85, 0.1, 0.1]
trousers_color = [0.8, 0.1, 0.1]
waypoints = [[4.58, 2.5]]
[[people]]
name = "blue"
shirt_color = [0.1, 0.2, 0.85]
trousers_color = [0.1, 0.15, 0.7]
waypoints = [[4.55, 4.0]]
"""


def write(tmp_path, text, name="two.toml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_two_cameras_see_their_targets_at_the_pinhole_columns(tmp_path):
    result = run_scenario(load_scenario(write(tmp_path, TWO_CAMERAS)), backend="model")
    t = result.trajectory
    f = 80 / math.tan(math.radians(30))
    # Frame 0, before anything moved: column = W/2 - f * tan(bearing), bearing left positive.
    body = 80 - f * (-0.5 / 3.0)  # 103.1
    pan = 80 - f * (1.0 / 3.0)  # 33.8
    assert t["found"][0] and t["turret.turret_found"][0] == 1
    assert t["centroid_x"][0] == pytest.approx(body, abs=2)
    assert t["turret.turret_centroid_x"][0] == pytest.approx(pan, abs=2)
    assert t["turret.target_bearing_deg"][0] == pytest.approx(math.degrees(math.atan(1 / 3)))
    # Its first command: the P law on that column, -(5 * (34 - 80)) >> 2 = +57 (turn left).
    cx = int(t["turret.turret_centroid_x"][0])
    assert t["pan.command"][1] == -((5 * (cx - 80)) >> 2)


@mujoco_missing
def test_both_cameras_see_the_pinhole_columns_in_3d_too(tmp_path):
    scenario = load_scenario(write(tmp_path, TWO_CAMERAS), ["camera.renderer=mujoco"])
    t = run_scenario(scenario, backend="model").trajectory
    f = 80 / math.tan(math.radians(30))
    assert t["centroid_x"][0] == pytest.approx(80 - f * (-0.5 / 3.0), abs=2)
    assert t["turret.turret_centroid_x"][0] == pytest.approx(80 - f * (1.0 / 3.0), abs=2)


def test_the_servo_slews_at_its_speed_after_the_actuation_delay(tmp_path):
    text = TWO_CAMERAS.replace("duration = 0.2", "duration = 0.6").replace(
        "height = 0.2\n[[robot.sensors]]", "height = 0.2\nspeed_deg_s = 60.0\n[[robot.sensors]]"
    )
    t = run_scenario(load_scenario(write(tmp_path, text)), backend="model").trajectory
    angle, command = t["pan.angle_deg"], t["pan.command"]
    # Frame 0's command acts one frame period (0.1 s) after its capture: row 1 holds it,
    # the horn has not moved yet; then 60 deg/s = 6 degrees per frame towards 0.18 deg/unit.
    assert angle[0] == angle[1] == 0.0 and command[1] > 0
    assert angle[2] == pytest.approx(6.0)
    assert angle[3] == pytest.approx(min(12.0, command[2] * 90 / 500), abs=1e-9)
    assert np.all(np.abs(np.diff(angle)) <= 6.0 + 1e-9)


@pytest.fixture(scope="module")
def turret_runs():
    good = run_scenario(load_scenario("turret"), backend="model")
    bad = run_scenario(
        load_scenario("turret", ["design.variant=turret_pan_inverted"]), backend="model"
    )
    return good, bad


def test_the_turret_keeps_its_target_centred_while_the_body_turns(turret_runs):
    good, _ = turret_runs
    t = good.trajectory
    settled = t["t"] >= 1.0
    heading = np.degrees(t["heading"][settled])
    assert heading.max() - heading.min() > 30  # the body turns while following the red person
    bearing = t["turret.target_bearing_deg"][settled]
    # The pan camera keeps the blue person within 7 degrees, half the time within 1, but for
    # the few frames after its search has turned it while the red person hid the blue one.
    assert np.mean(np.abs(bearing) < 7.0) > 0.98 and np.median(np.abs(bearing)) < 1.0
    assert np.max(np.abs(bearing)) < 15.0
    # ... because the servo turns against the body: the camera's world direction follows the
    # person's, whatever the heading.
    pan = t["pan.angle_deg"][settled]
    assert np.ptp(pan) > 20
    assert good.summary["verdict"] == "pass"
    assert good.summary["cameras"]["turret"]["target_centred_fraction"] >= 0.85


def test_the_inverted_pan_fails_the_centred_check(turret_runs):
    _, bad = turret_runs
    checks = {c["name"]: c["status"] for c in bad.summary["checks"]}
    assert checks["camera_target_centred_min_fraction"] == "fail"
    assert checks["max_person_collisions"] == "pass"  # the body's channel is unchanged


@pytest.mark.parametrize("seed", range(5))
def test_the_turret_searches_and_passes_a_minute(seed):
    """Over a minute the pan camera loses its person (the red one passes in front, the body
    turns); the search finds them again, so the camera checks pass, and without it (the
    angle held for ever) they fail."""
    s = load_scenario("turret", ["sim.duration=60"])
    r = run_scenario(s, seed=seed, backend="model")
    assert r.summary["verdict"] == "pass", [c["text"] for c in r.summary["checks"]]
    found = r.trajectory["turret.turret_found"].astype(bool)
    # Some loss outlasted lost_frames (the camera searched) and ended in a found frame.
    refound = np.flatnonzero(found[1:] & ~found[:-1]) + 1
    lost_before = [np.argmax(found[:i][::-1]) for i in refound]  # lost frames before each
    assert max(lost_before) > TurretParams().lost_frames
    if seed == 0:
        held = run_scenario(
            load_scenario("turret", ["sim.duration=60", "design.turret.search_step=0"]),
            seed=seed,
            backend="model",
        )
        checks = {c["name"]: c["status"] for c in held.summary["checks"]}
        assert checks["camera_target_in_view_min_fraction"] == "fail"


def test_the_viewer_shows_each_camera_and_its_view_on_the_map(tmp_path):
    path = tmp_path / "t.rrd"
    rec = open_recorder(f"save:{path}", default_path=str(path))
    seen = []
    result = run_scenario(
        load_scenario(write(tmp_path, TWO_CAMERAS)),
        backend="model",
        recorder=rec,
        on_frame=lambda record: seen.append(record.cameras["turret"].rgb.copy()),
    )
    rec.close()
    data = read_rrd(str(path))
    n = result.summary["frames"]
    assert data.entities[f"{CAMERAS}/turret/image"].frames == list(range(n))
    # Recorded as the design receives it (RGB444, shown as c << 4), losslessly.
    read = images(data, f"{CAMERAS}/turret/image")
    for k in (0, n // 2, n - 1):
        np.testing.assert_array_equal(read[k], seen[k] & 0xF0)
    # Its pinhole in the world: the 3D view shows the image on its frustum.
    placed = data.entities[f"{CAMERAS}/turret"].values["Transform3D:translation"][0][0]
    assert placed == pytest.approx((1.55, 3.0, 0.22))
    fov = data.entities[f"{MAP_CAMERAS}/turret"]
    _, (x, y), _ = fov.values["LineStrips2D:strips"][0][0]
    assert (x, -y) == pytest.approx((1.55, 3.0))  # the pan camera's place, y flipped back


def test_a_camera_on_a_missing_servo_is_a_clear_error(tmp_path):
    text = TWO_CAMERAS.replace('on = "pan"', 'on = "tilt"')
    with pytest.raises(UsageError, match="on = 'tilt' names no servo"):
        run_scenario(load_scenario(write(tmp_path, text)), backend="model")


def test_a_servo_on_a_port_no_channel_gives_is_refused_from_python_too(tmp_path):
    # The body camera's centroid_x is FollowTarget's output, not the turret channel's: in
    # compressed timing nothing would ever command the servo.
    text = TWO_CAMERAS.replace('kind = "servo"', 'kind = "servo"\nports = { angle = "centroid_x" }')
    with pytest.raises(UsageError, match="in compressed timing a servo hears an output of a"):
        run_scenario(load_scenario(write(tmp_path, text)), backend="model")


def test_the_cameras_benchmark_prints_both_runs_and_their_ratio(capsys, tmp_path):
    import json

    from fpga_robotics.bench.cameras import main

    assert main(["--seconds", "0.5", "--repeats", "1", "--json", str(tmp_path / "c.json")]) == 0
    out = capsys.readouterr().out
    assert "one camera:" in out and "two cameras:" in out
    figures = json.loads((tmp_path / "c.json").read_text())["figures"]
    two, one = figures["two cameras"]["frame_ms"], figures["one camera"]["frame_ms"]
    assert figures["ratio"] == pytest.approx(two["median"] / one["median"])
    assert f"two cameras / one camera: {figures['ratio']:.2f}" in out


def test_the_cameras_benchmark_warms_up_before_it_times(monkeypatch, capsys):
    """An untimed short run of each loop comes first, so that --repeats 1 is no cold run."""
    from types import SimpleNamespace

    from fpga_robotics.bench import cameras

    runs = []  # (connectors of the run, its simulated seconds), in order

    def run_scenario(scenario, backend):
        runs.append((len(scenario.connectors), scenario.sim.duration))
        return SimpleNamespace(summary={"frames": 1})

    monkeypatch.setattr(cameras, "run_scenario", run_scenario)
    assert cameras.main(["--seconds", "2", "--repeats", "1"]) == 0
    capsys.readouterr()
    # The pan camera and its servo are the turret's two connectors.
    assert runs == [(0, cameras.WARM_UP_S), (2, cameras.WARM_UP_S), (0, 2.0), (2, 2.0)]


def test_the_bag_has_each_camera_once_per_capture(tmp_path):
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    from fpga_robotics.ros.bag_writer import open_bag_writer

    # The body camera at 10 fps, the pan camera at 5: its frames at 0, 0.2 and 0.4 s.
    text = TWO_CAMERAS.replace("duration = 0.2", "duration = 0.6").replace(
        "fps = 10.0\nhfov_deg", "fps = 5.0\nhfov_deg"
    )
    scenario = load_scenario(write(tmp_path, text))
    bag = tmp_path / "bag"
    writer = open_bag_writer(bag, scenario)
    views = {}

    def on_frame(record):
        view = record.cameras["turret"]
        views[round(view.sim_time * 1e9)] = view
        writer.log_frame(record)

    run_scenario(scenario, backend="model", on_frame=on_frame)
    writer.close()
    out = {}
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS2_HUMBLE)) as reader:
        for conn, stamp, raw in reader.messages():
            out.setdefault(conn.topic, []).append((stamp, reader.deserialize(raw, conn.msgtype)))
    images = out["/cameras/turret/image_raw"]
    assert [stamp for stamp, _ in images] == [0, 200_000_000, 400_000_000] == sorted(views)
    for stamp, msg in images:
        assert msg.header.frame_id == "turret_optical_link"
        assert msg.data.tobytes() == views[stamp].rgb.tobytes()
    info = out["/cameras/turret/camera_info"][0][1]
    assert info.k[0] == pytest.approx(80 / math.tan(math.radians(30)))
    placed = [
        t.transform
        for _, m in out["/tf"]
        for t in m.transforms
        if t.child_frame_id == "turret_link"
    ]
    first = placed[0].translation
    assert (first.x, first.y, first.z) == pytest.approx((1.55, 3.0, 0.22))
    assert len(out["/camera/image_raw"]) == 6  # the body camera's, as before


def test_the_turret_campaign_runs_the_design_and_catches_its_bug(tmp_path):
    from fpga_robotics.sweep import load_campaign, run_campaign
    from fpga_robotics.sweep.campaign import read_campaign_file

    data = read_campaign_file("turret")
    data = dict(data[0] if isinstance(data, tuple) else data)
    data.update(seeds=[1], duration=4.0)
    rows = run_campaign(load_campaign(data), tmp_path, workers=1, record="none")
    by_set = {
        row["design.variant"] if row.get("design.variant") else "default": row for row in rows
    }
    assert by_set["default"]["status"] == "pass"
    bad = by_set["turret_pan_inverted"]
    assert bad["status"] == "fail" and "camera_target_centred_min_fraction" in bad["failed_checks"]
    direct = run_scenario(
        load_scenario("turret", ["sim.duration=4.0", "design.variant=turret_pan_inverted"]),
        seed=1,
        backend="model",
    ).summary
    assert bad["camera_target_centred_fraction"] == direct["camera_target_centred_fraction"]


@pytest.mark.slow  # builds the CXXRTL model of TurretTracker
def test_real_clock_streams_the_pan_camera_and_agrees_on_the_first_frame(tmp_path):
    path = write(tmp_path, TWO_CAMERAS)
    # A 1 MHz clock: 787 cycles a line at 10 fps, room for 160 pixels every 4 cycles.
    common = ["sim.clock_hz=1000000", "sim.duration=0.35"]
    frames = run_scenario(
        load_scenario(path, [*common, "sim.timing=compressed"]), backend="model"
    ).trajectory
    clock = run_scenario(load_scenario(path, [*common, "sim.timing=real_clock"]), backend="cxxrtl")
    t = clock.trajectory
    assert clock.summary["timing"] == "real_clock"
    # Frame 0, captured before anything moved, streams over the frame period: row 1 shows
    # its result, the same as the compressed run's row 0, and the same first command.
    assert t["turret.turret_found"][1] == 1
    assert t["turret.turret_centroid_x"][1] == frames["turret.turret_centroid_x"][0]
    assert t["pan.command"][1] == frames["turret.servo_angle"][0]
    # The command acts 1 ms after the pin changes, on the next physics step: the horn has
    # turned by whole steps of 2.5 degrees (600 deg/s at 240 steps a second) by row 1.
    assert t["pan.angle_deg"][1] / 2.5 == pytest.approx(round(t["pan.angle_deg"][1] / 2.5))
    assert 0 < t["pan.angle_deg"][1] <= 2.5 * round((0.1 - 0.094) * 240 + 1)


@pytest.mark.parametrize(
    "old, new, message",
    [
        (
            'resolution = "160x120"\nfps = 15.0\nhfov_deg',
            'resolution = "160by120"\nfps = 15.0\nhfov_deg',
            "robot.sensors[0].resolution must look like WIDTHxHEIGHT",
        ),
        ('color = "blue"', 'color = "purple"', "robot.sensors[0].color must be one of"),
        ("centred_deg = 10.0", "centred = 10.0", "unknown key 'centred' for a 'camera' connector"),
        ("speed_deg_s = 600.0", "speed_deg_s = 0.0", "robot.actuators[0].speed_deg_s must be"),
        ("speed_deg_s = 600.0", "range = 90", "unknown key 'range' for a 'servo' connector"),
    ],
)
def test_bad_camera_and_servo_keys_are_named(tmp_path, old, new, message):
    from fpga_robotics.scenario.load import ScenarioError, shipped_scenarios

    text = Path(shipped_scenarios()["turret"][0]).read_text()
    assert old in text
    with pytest.raises(ScenarioError, match=re.escape(message)):
        load_scenario(write(tmp_path, text.replace(old, new)))


def test_a_further_cameras_field_of_view_is_checked_at_load():
    from fpga_robotics.scenario.load import ScenarioError

    # 170 degrees wide at 160x120: f = 80 / tan(85 deg) = 7.0 px, half the vertical field of
    # view atan(60 / f) = 83.35 deg, so the rows stay 0.02 rad (1.15 deg) off vertical while
    # |tilt| <= 90 - 1.15 - 83.35 = 5.5 deg.
    wide = ["robot.sensors[0].hfov_deg=170", "sim.duration=0.1"]
    with pytest.raises(ScenarioError) as info:
        load_scenario("turret", [*wide, "robot.sensors[0].tilt_deg=10"])
    assert str(info.value).startswith(
        "|robot.sensors[0].tilt_deg| must be at most 5.5 deg with its hfov_deg 170 at 160x120"
    )
    # At the printed limit the renderer draws every frame (it refused mid-run before).
    result = run_scenario(
        load_scenario("turret", [*wide, "robot.sensors[0].tilt_deg=-5.5"]), backend="model"
    )
    assert result.summary["cameras"]["turret"]["frames"] == 2  # at 15 frames a second
    # 16x1000: even level, the rows stay off vertical only while hfov <= 2 atan(16 / 1000 *
    # cot(0.02)) = 77.32 deg.
    with pytest.raises(ScenarioError, match=r"robot.sensors\[0\].hfov_deg must be at most 77.31"):
        load_scenario("turret", ['robot.sensors[0].resolution="16x1000"', *wide])


def test_the_sensor_model_makes_every_cameras_frames():
    def frames(sensor, seed):
        scenario = load_scenario("turret", ["sim.duration=0.2", f"camera.sensor={sensor}"])
        assert not any("camera.sensor" in w for w in scenario.warnings)
        pan, body = [], []

        def keep(record):
            pan.append(record.cameras["turret"].rgb.copy())
            body.append(record.camera_rgb.copy())

        run_scenario(scenario, seed=seed, backend="model", on_frame=keep)
        return np.array(pan), np.array(body)

    (plain, _), (ov7670, body) = frames("plain", 0), frames("ov7670", 0)
    # With the sensor model the pan camera sends the OV7670's RGB444 as the body camera does
    # (low nibbles 0); the plain path is the rendered frame plus its noise_std.
    assert np.any(plain & 0x0F) and not np.any(ov7670 & 0x0F) and not np.any(body & 0x0F)
    # Its sensor noise comes from the seed, on a stream of its own.
    again, other = frames("ov7670", 0)[0], frames("ov7670", 1)[0]
    assert np.array_equal(again, ov7670) and not np.array_equal(other, ov7670)


def test_any_number_of_cameras_each_on_its_own_mount(tmp_path):
    # A third camera on the body, looking left (yaw 90 degrees), filming only, watching blue:
    # from (1.5, 3.0) the blue person at (4.55, 4.0) is atan2(1.0, 3.05) - 90 = -71.8 degrees
    # off its axis, outside its 60 degrees.
    side = """
[[robot.sensors]]
kind = "camera"
name = "side"
yaw_deg = 90.0
height = 0.15
resolution = "80x60"
fps = 5.0
target = "blue"

[[robot.sensors]]
kind = "camera"
name = "rear"
yaw_deg = 180.0
height = 0.15
resolution = "80x60"
fps = 5.0
"""
    text = TWO_CAMERAS.replace("[[people]]", side + "[[people]]", 1)
    records = []
    result = run_scenario(
        load_scenario(write(tmp_path, text)), backend="model", on_frame=records.append
    )
    t = result.trajectory
    expected = math.degrees(math.atan2(1.0, 3.05)) - 90
    assert t["side.target_bearing_deg"][0] == pytest.approx(expected)
    assert t["side.target_in_view"][0] == 0
    assert t["turret.target_in_view"][0] == 1  # the pan camera sees blue at the same instant
    assert set(records[0].cameras) == {"turret", "side", "rear"}
    assert records[0].cameras["side"].rgb.shape == (60, 80, 3)
    cams = result.summary["cameras"]
    assert (cams["side"]["channel"], cams["turret"]["channel"]) == (None, "model")
    assert cams["side"]["frames"] == 1 and cams["turret"]["frames"] == 2  # 5 and 10 fps, 0.2 s
    # A camera without a target is listed too, with nothing to judge.
    assert cams["rear"] == {
        "frames": 1,
        "channel": None,
        "target_in_view_fraction": None,
        "target_centred_fraction": None,
        "max_abs_bearing_deg": None,
    }
    assert result.summary["camera_target_in_view_fraction"] == 0.0  # side's, not rear's
