"""Terrain and drive uncertainty against hand-computed physics (sim/world/terrain.py,
sim/world/uncertainty.py): a robot parked on a ramp slides exactly when ``m g sin(theta)``
exceeds its traction, a low-traction patch limits the acceleration to ``k F / m``, the camera
pitches with the slope by ``atan(tan(theta) cos(heading - dir))`` and the target's image row
moves by the pinhole model's amount, the noise has the statistics its parameters say, and
the same seed gives the same run."""

import math
import re

import numpy as np
import pytest

from fpga_robotics.sim.camera.raster import CameraRenderer, focal_length
from fpga_robotics.sim.world import World
from fpga_robotics.sim.world.config import Uncertainty, WorldConfigError
from fpga_robotics.sim.world.robots import ROBOT_MODELS, TURTLEBOT2, G
from fpga_robotics.sim.world.terrain import TerrainPatch, polygon_contains, slope_pitch
from fpga_robotics.sim.world.uncertainty import NOISE_TAU, MotorUncertainty

DT = 1 / 200
DEG = math.pi / 180


def run(world, seconds):
    for _ in range(round(seconds / DT)):
        world.step(DT)


def ramp_world(slope_deg, *, friction=1.0, slope_dir_deg=0.0, robot=None, people=()):
    room = {
        "width": 8.0,
        "depth": 6.0,
        "terrain": [
            {
                "name": "ramp",
                "center": [4.0, 3.0],
                "size": [6.0, 4.0],
                "friction": friction,
                "slope_deg": slope_deg,
                "slope_dir_deg": slope_dir_deg,
            }
        ],
    }
    return World.from_config(
        {"room": room, "robot": {"start": [4.0, 3.0], **(robot or {})}, "people": list(people)},
        seed=0,
    )


def test_polygons_and_the_last_patch_wins():
    square = ((0, 0), (2, 0), (2, 2), (0, 2))
    assert polygon_contains(square, 1, 1) and not polygon_contains(square, 3, 1)
    l_shape = ((0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3))
    assert polygon_contains(l_shape, 0.5, 2.5) and not polygon_contains(l_shape, 2, 2)
    world = World.from_config(
        {
            "room": {
                "terrain": [
                    {"name": "carpet", "center": [3, 3], "size": [4, 4], "friction": 0.5},
                    {"name": "wet", "points": [[2, 2], [4, 2], [4, 4], [2, 4]], "friction": 0.1},
                ]
            },
            "robot": {"start": [1.5, 3.0]},
            "people": [],
        },
        seed=0,
    )
    assert world.terrain.at(3, 3).name == "wet"  # listed last
    assert world.terrain.at(1.5, 3).name == "carpet"
    assert world.terrain.at(6, 3) is None


# Slopes -----------------------------------------------------------------------------------------

#: The TurtleBot2 holds on a ramp while m g sin(theta) <= traction_force: 12.6 N / (6.3 kg g).
CRITICAL_DEG = math.degrees(math.asin(TURTLEBOT2.traction_force / (TURTLEBOT2.mass * G)))


@pytest.mark.parametrize("slope_deg", [CRITICAL_DEG - 1.5, CRITICAL_DEG + 2.0])
def test_a_parked_robot_slides_exactly_when_gravity_beats_traction(slope_deg):
    world = ramp_world(slope_deg, slope_dir_deg=90.0)  # the ramp rises towards +y
    run(world, 1.0)
    x, y, _ = world.robot_pose()
    m, f = TURTLEBOT2.mass, TURTLEBOT2.traction_force
    excess = m * G * math.sin(slope_deg * DEG) - f
    if excess <= 0:
        assert abs(y - 3.0) < 1e-3 and abs(x - 4.0) < 1e-3
    else:
        # Newton: the wheels resist with their whole traction, a = excess / m, s = a t^2 / 2.
        expected = 0.5 * excess / m * 1.0**2
        assert 3.0 - y == pytest.approx(expected, rel=0.05)
        assert abs(x - 4.0) < 1e-3  # straight downhill


@pytest.mark.parametrize("model", ["turtlebot2", "gopigo3"])
@pytest.mark.parametrize("heading_deg", [90.0, -90.0, 0.0])  # uphill, downhill, across
@pytest.mark.parametrize("margin_deg", [-1.0, 1.0])
def test_a_robot_parked_on_a_steep_ramp_tips_when_its_centre_of_mass_leaves_the_support(
    model, heading_deg, margin_deg
):
    # The ramp's grip (friction 10) holds the robot; facing up or down the slope it falls
    # over once its centre of mass, com_height above the floor, leans past the support edge
    # support_half_length from it: tan(slope) > support_half_length / com_height (TurtleBot2
    # 29.9 deg, GoPiGo3 38.7 deg). Across the slope it does not pitch: it falls on its side
    # where tan(slope) > support_half_width / com_height (29.9 and 23.1 deg), as below.
    spec = ROBOT_MODELS[model]
    slope = math.degrees(math.atan(spec.support_half_length / spec.com_height)) + margin_deg
    world = ramp_world(
        slope, friction=10.0, slope_dir_deg=90.0, robot={"model": model, "heading_deg": heading_deg}
    )
    run(world, 0.5)
    if heading_deg == 0.0:
        sideways = math.tan(slope * DEG) > spec.support_half_width / spec.com_height
        assert (world.tipped is not None) == sideways
        return
    tips = margin_deg > 0
    assert (world.tipped is not None) == tips
    if tips:
        assert f"on a {'+' if heading_deg > 0 else '-'}{slope:.1f} deg slope" in world.tipped[1]


@pytest.mark.parametrize("model", ["turtlebot2", "gopigo3"])
@pytest.mark.parametrize("heading_deg", [0.0, 180.0])  # the slope rising to its left, right
@pytest.mark.parametrize("margin_deg", [-1.0, 1.0])
def test_a_robot_parked_across_a_steep_ramp_falls_on_its_downhill_side(
    model, heading_deg, margin_deg
):
    # Across the slope the centre of mass leans sideways towards the downhill wheel: it falls
    # once tan(slope) > support_half_width / com_height (TurtleBot2: the wheel contact 0.115 m
    # out, 29.9 deg; GoPiGo3: the edge from a wheel to the rear caster 0.032 m out, 23.1 deg),
    # while the ramp's grip (friction 10) holds it there.
    spec = ROBOT_MODELS[model]
    critical = math.degrees(math.atan(spec.support_half_width / spec.com_height))
    assert critical == pytest.approx({"turtlebot2": 29.9, "gopigo3": 23.1}[model], abs=0.05)
    world = ramp_world(
        critical + margin_deg,
        friction=10.0,
        slope_dir_deg=90.0,
        robot={"model": model, "heading_deg": heading_deg},
    )
    run(world, 0.5)
    assert (world.tipped is not None) == (margin_deg > 0)
    if margin_deg > 0:
        # Facing +x the ramp rises to its left: it falls to its right, and the other way.
        side = "right" if heading_deg == 0.0 else "left"
        assert world.tipped[0] < 0.01
        assert f"on its {side} side: rolled {critical + margin_deg:.1f} deg" in world.tipped[1]


def test_a_robot_sliding_sideways_down_a_ramp_does_not_fall():
    # A GoPiGo3 across a 30 deg ramp on a plain floor: gravity's sideways pull, g sin 30 =
    # 4.9 m/s^2, beats its traction (1.39 N / 0.8 kg = 1.74 m/s^2), so it slides, and the
    # floor leans it only by what the traction gives, below g * 0.032 / 0.075 * cos 30 = 3.6.
    world = ramp_world(30.0, slope_dir_deg=90.0, robot={"model": "gopigo3"})
    run(world, 0.5)
    assert world.tipped is None
    assert world.robot_pose()[1] < 3.0 - 0.05  # it slid downhill


def test_driving_uphill_keeps_the_wheels_speed_while_traction_holds():
    world = ramp_world(5.0, slope_dir_deg=0.0, robot={"start": [2.0, 3.0]})
    world.set_wheel_dps(300, 300)
    run(world, 2.0)
    v, _ = world.robot_velocity()
    assert v == pytest.approx(0.035 * 300 * DEG, rel=1e-3)


@pytest.mark.parametrize("heading_deg, expected_deg", [(0, 10.0), (180, -10.0), (90, 0.0)])
def test_the_camera_pitches_with_the_slope(heading_deg, expected_deg):
    patch = TerrainPatch("r", ((0, 0), (1, 0), (1, 1)), 1.0, 10 * DEG, 0.0, None)
    assert math.degrees(slope_pitch(patch, heading_deg * DEG)) == pytest.approx(expected_deg)
    oblique = math.degrees(slope_pitch(patch, 60 * DEG))
    assert oblique == pytest.approx(math.degrees(math.atan(math.tan(10 * DEG) * 0.5)))
    world = ramp_world(10.0, robot={"heading_deg": heading_deg})
    pose = world.camera_pose()
    assert math.degrees(pose.tilt - TURTLEBOT2.camera_tilt) == pytest.approx(expected_deg)


def test_each_camera_pitches_along_the_way_it_faces():
    from fpga_robotics.loop.timings import run_scenario
    from fpga_robotics.scenario.load import load_scenario

    # On the shipped 9 degree ramp (rising towards +x), facing uphill: the body camera turned
    # 45 degrees left pitches atan(tan 9 cos 45) = 6.39 degrees, a rear camera faces downhill
    # (-9), a side camera across the slope (0, only its own tilt).
    cameras = (
        '[{kind="camera", name="rear", height=0.4, yaw_deg=180.0},'
        ' {kind="camera", name="side", height=0.4, yaw_deg=90.0, tilt_deg=-5.0}]'
    )
    scenario = load_scenario(
        "ramp",
        [
            "robot.start=[4.0, 3.0]",
            "sim.duration=0.05",
            "camera.yaw_offset_deg=45",
            f"robot.sensors={cameras}",
        ],
    )
    records = []
    run_scenario(scenario, backend="model", on_frame=records.append)
    first = records[0]
    oblique = math.degrees(math.atan(math.tan(9 * DEG) * math.cos(45 * DEG)))
    assert math.degrees(first.camera_pose.tilt - TURTLEBOT2.camera_tilt) == pytest.approx(oblique)
    assert math.degrees(first.cameras["rear"].pose.tilt) == pytest.approx(-9.0)
    assert math.degrees(first.cameras["side"].pose.tilt) == pytest.approx(-5.0)


def _top_row(rgb, col, color):
    """The first row from the top of column ``col`` where the shirt's colour is."""
    c = rgb[:, col].astype(int)
    hit = np.nonzero((c[:, 0] > 120) & (c[:, 1] < 60) & (c[:, 2] < 60))[0]
    return int(hit[0]) if len(hit) else None


def test_the_pitch_moves_the_targets_image_row_by_the_pinhole_amount():
    person = {
        "name": "t",
        "target": True,
        "waypoints": [[7.0, 3.0]],
        "shirt_color": [0.9, 0.05, 0.05],
    }
    width, height, hfov = 160, 120, 1.047
    renderer = CameraRenderer(width, height, hfov)
    f = focal_length(width, hfov)
    rows = {}
    for slope in (0.0, 6.0):
        world = ramp_world(slope, robot={"start": [2.0, 3.0]}, people=[person])
        pose = world.camera_pose()
        scene = world.scene()
        rgb = renderer.render(scene, pose)
        (cyl,) = scene.cylinders
        shirt = next(b for b in cyl.bands if b.color == (0.9, 0.05, 0.05))
        depth = (cyl.x - cyl.radius) - pose.x  # the nearest point, on the optical axis
        elevation = math.atan((shirt.z1 - pose.height) / depth)
        # row centre = H/2 - 0.5 - f tan(elevation - tilt): the first row below the edge.
        edge = height / 2 - 0.5 - f * math.tan(elevation - pose.tilt)
        rows[slope] = (_top_row(rgb, width // 2, None), edge)
    for got, edge in rows.values():
        assert got is not None and abs(got - edge) <= 1.0
    # Looking up the ramp, the target sits lower in the image by the pinhole amount.
    assert rows[6.0][0] - rows[0.0][0] == pytest.approx(rows[6.0][1] - rows[0.0][1], abs=1.0)
    assert rows[6.0][0] - rows[0.0][0] >= 8


# Traction patches -----------------------------------------------------------------------------


@pytest.mark.parametrize("k", [1.0, 0.25])
def test_a_patch_scales_the_acceleration_by_its_traction_factor(k):
    # Motors that ramp almost at once: the body's acceleration is traction-limited, k F / m.
    world = ramp_world(0.0, friction=k, robot={"start": [2.0, 3.0], "wheel_accel_dps2": 1e5})
    world.set_wheel_dps(600, 600)
    run(world, 0.1)
    v, _ = world.robot_velocity()
    assert v == pytest.approx(k * TURTLEBOT2.traction_force / TURTLEBOT2.mass * 0.1, rel=0.06)


# Uncertainty ----------------------------------------------------------------------------------


def test_speed_noise_has_the_stated_deviation_and_correlation_time():
    u = MotorUncertainty(Uncertainty(motor_noise_dps=20.0), seed=4)
    h, n = 0.005, 200_000
    noise = np.array([u.step(h, 0.0, 0.0, i * h)[0] for i in range(n)])
    sigma = 20.0 * DEG
    assert noise.std() == pytest.approx(sigma, rel=0.05)
    lag = round(NOISE_TAU / h)
    r = np.corrcoef(noise[:-lag], noise[lag:])[0, 1]
    assert r == pytest.approx(math.exp(-1), abs=0.05)


def test_gain_errors_are_drawn_once_within_bounds_and_seeded():
    a = MotorUncertainty(Uncertainty(motor_gain_error=0.1), seed=7)
    b = MotorUncertainty(Uncertainty(motor_gain_error=0.1), seed=7)
    c = MotorUncertainty(Uncertainty(motor_gain_error=0.1), seed=8)
    assert a.gains == b.gains != c.gains
    assert all(0.9 <= g <= 1.1 for g in a.gains)
    left, right, traction = a.step(0.01, 10.0, 10.0, 0.0)
    assert (left, right, traction) == (10.0 * a.gains[0], 10.0 * a.gains[1], 1.0)


def test_slips_come_at_their_rate_and_cut_the_traction():
    rate, duration, h = 0.5, 0.2, 0.01
    u = MotorUncertainty(
        Uncertainty(slip_rate_hz=rate, slip_duration_s=duration, slip_traction=0.3), seed=1
    )
    total = 4000.0
    slipping = 0
    for i in range(round(total / h)):
        slipping += u.step(h, 1.0, 1.0, i * h)[2] == 0.3
    events = len(u.drain_events())
    # Starts come at `rate` while not slipping: expected events = rate * (T - events * d).
    expected = rate * total / (1 + rate * duration)
    assert abs(events - expected) < 4 * math.sqrt(expected)
    assert slipping * h == pytest.approx(events * duration, rel=0.02)


def test_the_same_seed_gives_the_same_run_and_the_ideal_robot_is_unchanged():
    robot = {
        "start": [2.0, 3.0],
        "motor_gain_error": 0.05,
        "motor_noise_dps": 15.0,
        "slip_rate_hz": 1.0,
    }

    def drive(cfg, seed):
        world = World.from_config({"robot": cfg, "people": []}, seed=seed)
        world.set_wheel_dps(200, 260)
        run(world, 3.0)
        return world.robot_pose(), world.drain_events()

    assert drive(robot, 3) == drive(robot, 3)
    assert drive(robot, 3) != drive(robot, 4)
    ideal = drive({"start": [2.0, 3.0]}, 3)
    zeros = drive({"start": [2.0, 3.0], "motor_gain_error": 0.0, "motor_noise_dps": 0.0}, 3)
    assert ideal == zeros  # bit for bit: nothing drawn, nothing changed


@pytest.mark.parametrize(
    "room, message",
    [
        ({"terrain": {"center": [1, 1]}}, "room.terrain must be an array of tables"),
        ({"terrain": [{"friction": 0.5}]}, "room.terrain[0] needs either points"),
        (
            {"terrain": [{"center": [1, 1], "points": [[0, 0], [1, 0], [1, 1]]}]},
            "room.terrain[0] needs either points",
        ),
        (
            {"terrain": [{"points": [[0, 0], [1, 0]]}]},
            ("room.terrain[0].points must be an array of at least 3 points"),
        ),
        ({"terrain": [{"points": [[0, 0], [1, 1], [2, 2]]}]}, "encloses no area"),
        (
            # A bow tie: its lobes' signed areas cancel, but its points are not on a line.
            {"terrain": [{"points": [[1, 1], [3, 3], [3, 1], [1, 3]]}]},
            (
                "room.terrain[0].points cross themselves: the edge points[0] -> [1] crosses "
                "points[2] -> [3]"
            ),
        ),
        (
            {"terrain": [{"points": [[2, 1], [5, 4], [5, 1], [2, 5]]}]},
            "room.terrain[0].points cross themselves",
        ),
        (
            {"terrain": [{"points": [[1, 1], [4, 1], [4, 3], [2, 3], [2, 0.5], [1, 2]]}]},
            "the edge points[0] -> [1] crosses points[3] -> [4]",
        ),
        (
            {"terrain": [{"center": [1, 1], "slope_deg": 60}]},
            "room.terrain[0].slope_deg must be <= 45",
        ),
        (
            {"terrain": [{"center": [1, 1], "friction": 0}]},
            "room.terrain[0].friction must be >= 0.01",
        ),
        (
            {"terrain": [{"center": [1, 1], "colour": [1, 0, 0]}]},
            ("room.terrain[0].colour is not a known key (did you mean 'color'?)"),
        ),
        ({"terrain": [{"center": [50, 50]}]}, "room.terrain[0] lies outside the room"),
    ],
)
def test_bad_terrain_names_the_key(room, message):
    with pytest.raises(WorldConfigError, match=re.escape(message)):
        World.from_config({"room": room, "people": []}, seed=0)


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("motor_gain_error", 1.5, "robot.motor_gain_error must be <= 0.9"),
        ("motor_noise_dps", -1, "robot.motor_noise_dps must be >= 0"),
        ("slip_rate_hz", "often", "robot.slip_rate_hz must be a number"),
        ("slip_traction", 0, "robot.slip_traction must be >= 0.01"),
    ],
)
def test_bad_uncertainty_names_the_key(key, value, message):
    with pytest.raises(WorldConfigError, match=message):
        World.from_config({"robot": {key: value}, "people": []}, seed=0)


def test_the_map_shows_the_terrain(tmp_path):
    from fpga_robotics.loop.timings import run_scenario
    from fpga_robotics.scenario.load import load_scenario
    from fpga_robotics.viz import open_recorder
    from fpga_robotics.viz import paths as P
    from fpga_robotics.viz.readback import read_rrd

    path = tmp_path / "slippery.rrd"
    rec = open_recorder(f"save:{path}", default_path=None)
    run_scenario(
        load_scenario("slippery", ['camera.resolution="80x60"', "sim.duration=0.2"]),
        backend="model",
        recorder=rec,
    )
    rec.close()
    recording = read_rrd(str(path))
    static = recording.static[P.MAP_TERRAIN]
    (strip,) = static["LineStrips2D:strips"]
    # The wet strip's outline, closed (5 points), in the viewer's coordinates (y down).
    assert sorted({round(p[0], 4) for p in strip}) == [2.6, 4.6]
    assert sorted({round(abs(p[1]), 4) for p in strip}) == [0.0, 6.0] and len(strip) == 5


def test_a_robot_starting_on_a_patch_logs_it_first():
    cfg = {
        "room": {
            "width": 8,
            "depth": 6,
            "terrain": [
                {"name": "carpet", "center": [2, 3], "size": [2, 2], "friction": 0.5},
                {"name": "wet", "center": [5, 3], "size": [1, 2], "friction": 0.3},
            ],
        },
        "robot": {"start": [2, 3]},
        "people": [],
    }
    world = World.from_config(cfg, 0)
    assert world.drain_events() == ["terrain: on 'carpet'"]
    world.set_wheel_dps(600, 600)
    events = []
    for _ in range(240 * 8):
        world.step(1 / 240)
        events += world.drain_events()
    # It leaves the carpet (x = 3 m) and reaches the wet patch (x = 4.5 m) within 8 s.
    assert events == ["terrain: off the patches", "terrain: on 'wet'"]
    # A start off every patch logs nothing.
    assert World.from_config(dict(cfg, robot={"start": [1, 1]}), 0).drain_events() == []
