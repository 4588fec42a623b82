"""Scenario files: loading, defaults, overrides and the errors a user sees."""

import math

import numpy as np
import pytest

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import (
    ScenarioError,
    load_scenario,
    parse_resolution,
    shipped_scenarios,
)

SHIPPED = ("follow_person", "divider", "lighting", "heavy_robot", "lost_target")

MINIMAL = """
name = "mini"
[sim]
duration = 2.0
[checks]
acquired_within_s = 1.5
"""


def write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_world_sections_are_defined_once_by_the_world():
    from fpga_robotics.scenario import load as scenario
    from fpga_robotics.sim.world import config

    assert scenario.WORLD_SECTIONS is config.WORLD_SECTIONS


def test_the_five_scenarios_are_shipped_and_load():
    names = set(shipped_scenarios())
    assert set(SHIPPED) <= names
    for name in SHIPPED:
        s = load_scenario(name)
        assert s.name == name
        assert s.description, f"{name} has no description"
        assert s.checks, f"{name} states no pass criteria"
        assert s.params.width == s.camera.width and s.params.height == s.camera.height


def test_the_readme_names_every_shipped_scenario():
    """The README's "Scenarios (...) are TOML files" reads as the full list."""
    import re
    from pathlib import Path

    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    listing = re.search(r"Scenarios \((.*?)\)\s+are TOML files", readme, re.DOTALL)
    assert listing, "README.md lost its list of scenarios"
    assert set(re.findall(r"`(\w+)`", listing.group(1))) == set(shipped_scenarios())


def test_defaults_fill_the_application_sections(tmp_path):
    s = load_scenario(write(tmp_path, MINIMAL))
    assert s.name == "mini" and s.seed == 0
    assert (s.camera.width, s.camera.height, s.camera.fps, s.camera.hfov) == (160, 120, 30.0, 1.047)
    # The actuation delay defaults to one frame period.
    assert s.sim.actuation_delay == pytest.approx(1 / 30)
    assert s.sim.duration == 2.0 and s.color_initial == "red" and s.color_changes == ()
    # Mount left to the robot model.
    assert s.camera.mount_height is None
    assert s.checks == {"acquired_within_s": 1.5}


def test_the_name_defaults_to_the_file_stem(tmp_path):
    s = load_scenario(write(tmp_path, "[sim]\nduration = 1.0\n", "my_room.toml"))
    assert s.name == "my_room"


def test_overrides_are_toml_typed(tmp_path):
    path = write(tmp_path, MINIMAL)
    s = load_scenario(
        path,
        [
            "sim.duration=7",  # an int where a float was: a float
            "camera.fps=15",
            "color.initial=green",  # a bare word is a string
            'camera.resolution="320x240"',
            "design.kp_num=2",
            "design.base_dps=[0, 200, 150, 100, 80, 50, -50, -80]",
            "seed=42",
            "checks.max_person_collisions=0",
        ],
    )
    assert s.sim.duration == 7.0 and isinstance(s.data["sim"]["duration"], float)
    assert s.camera.fps == 15.0 and s.sim.actuation_delay == pytest.approx(1 / 15)
    assert s.color_initial == "green"
    assert (s.params.width, s.params.height) == (320, 240)
    assert s.params.area_scale == 4 and s.params.min_pixels == 512  # derived from the geometry
    assert s.params.kp_num == 2 and s.params.base_dps[1] == 200
    assert s.seed == 42
    assert s.checks["max_person_collisions"] == 0
    assert s.overrides[0] == "sim.duration=7"


def test_world_overrides_reach_the_world_config():
    s = load_scenario("follow_person", ["robot.mass=12", "people.0.speed=0.25"])
    assert s.world["robot"]["mass"] == 12
    assert s.world["people"][0]["speed"] == 0.25


def test_with_overrides_keeps_earlier_ones():
    s = load_scenario("follow_person", ["sim.duration=3"]).with_overrides(["design.kp_num=1"])
    assert s.sim.duration == 3.0 and s.params.kp_num == 1
    assert s.overrides == ("sim.duration=3", "design.kp_num=1")


def test_with_overrides_lists_each_key_once_with_the_value_in_force():
    base = load_scenario("follow_person", ["design.kp_num=2", "people[0].speed=0.2"])
    s = base.with_overrides(["design.kp_num=5", "people=[]"])
    assert s.overrides == ("design.kp_num=5", "people=[]")
    # Loaded again from its own list, it is the same scenario.
    assert load_scenario("follow_person", s.overrides).params == s.params


def test_override_without_a_key_says_what_set_needs():
    # It said "unknown scenario key ''".
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", ["=3"])
    assert str(info.value) == "--set needs KEY=VALUE (e.g. robot.mass=12), got '=3'"


def test_overrides_given_as_one_string_are_refused_as_such():
    # It was taken a character at a time: "--set needs KEY=VALUE ..., got 's'".
    expected = (
        'overrides must be a list of "KEY=VALUE" strings, got the string '
        "'sim.duration=2'; write ['sim.duration=2']"
    )
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", "sim.duration=2")
    assert str(info.value) == expected
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person").with_overrides("sim.duration=2")
    assert str(info.value) == expected


def test_colour_changes_take_effect_at_their_time(tmp_path):
    s = load_scenario(
        write(
            tmp_path,
            MINIMAL
            + """
[color]
initial = "red"
changes = [{at = 1.0, color = "green"}, {at = 2.5, color = "none"}]
""",
        )
    )
    assert [s.color_at(t) for t in (0.0, 0.99, 1.0, 2.0, 2.5, 9.0)] == [
        "red",
        "red",
        "green",
        "green",
        "none",
        "none",
    ]


@pytest.mark.parametrize(
    "item,expect",
    [
        ("design.kp=1", "design.kp_num"),
        ("sim.duratoin=3", "sim.duration"),
        ("camera.fsp=3", "camera.fps"),
        ("checks.acquired_within=3", "checks.acquired_within_s"),
        ("robot.mas=12", "mass"),  # the world names its known keys
        ("people.0.sped=1", "speed"),
    ],
)
def test_unknown_keys_are_errors_with_close_matches(item, expect):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [item])
    assert item.split("=")[0].split(".")[-1] in str(info.value)
    assert expect in str(info.value)


@pytest.mark.parametrize(
    "item,fragment",
    [
        ("design.width=320", "camera.resolution"),
        ("people.5.speed=1", "index it with 0..0"),
        ("color.changes.0.at=2", "color.changes is an empty list; set it whole: --set 'color."),
        ("room.furniture.0.height=1", "the scenario has no room.furniture to index"),
        ("robot.sensors.0.height=1", "the scenario has no robot.sensors to index; set it whole"),
        ("robot.actuators.0.range_deg=9", "the scenario has no robot.actuators to index"),
        ("lighting.keyframes.0=1", "the scenario has no lighting.keyframes to index"),
        ("people=5", "people must be an array of tables ([[people]] in a file"),
        ("room=5", "[room] must be a table, got 5"),
        ("sim.duration", "KEY=VALUE"),
        ("sim.duration=-1", "sim.duration must be > 0"),
        ("sim.physics_dt=0.5", "sim.physics_dt 0.5 s is longer than a camera frame period"),
        ("camera.resolution=abc", "camera.resolution must look like WIDTHxHEIGHT"),
        ("color.initial=purple", "color.initial must be one of"),
        ("design.kp_num=1.5", "kp_num must be an int"),
        (
            "checks.max_person_collisions=-1",
            "checks.max_person_collisions must be an integer in 0..1000000, got -1",
        ),
        ("robot.mass=-1", "robot.mass"),
    ],
)
def test_bad_values_are_clear_errors(item, fragment):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [item])
    assert fragment in str(info.value)


def test_unknown_scenario_lists_the_shipped_ones():
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_persn")
    msg = str(info.value)
    assert "follow_persn" in msg and "did you mean follow_person" in msg
    for name in SHIPPED:
        assert name in msg
    assert isinstance(info.value, UsageError)


def test_missing_file_is_a_clear_error(tmp_path):
    with pytest.raises(ScenarioError, match="does not exist"):
        load_scenario(str(tmp_path / "nope.toml"))


def test_malformed_toml_names_the_line(tmp_path):
    path = write(tmp_path, "[sim]\nduration = 2.0\n\n[camera\nfps = 30\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    msg = str(info.value)
    assert str(path) in msg and "malformed TOML" in msg and "line 4" in msg


def test_unknown_keys_in_the_file_are_errors(tmp_path):
    with pytest.raises(ScenarioError, match=r"sim\.duraton.*did you mean sim\.duration"):
        load_scenario(write(tmp_path, "[sim]\nduraton = 2.0\n"))
    with pytest.raises(ScenarioError, match="unknown top-level key 'camrea'"):
        load_scenario(write(tmp_path, "[camrea]\nfps = 2.0\n"))


def test_parse_resolution():
    assert parse_resolution("640x480") == (640, 480)
    assert parse_resolution("320X240") == (320, 240)
    assert parse_resolution([160, 120]) == (160, 120)
    for bad in ("640", "x480", "640x", "-1x2", "axb", "1x2x3", 640):
        with pytest.raises(ScenarioError):
            parse_resolution(bad)


def test_actuation_delay_can_be_zero(tmp_path):
    s = load_scenario(write(tmp_path, MINIMAL), ["sim.actuation_delay=0.0"])
    assert s.sim.actuation_delay == 0.0
    assert math.isclose(s.camera.frame_period, 1 / 30)


def test_placement_errors_are_found_at_load_time():
    with pytest.raises(ScenarioError, match="overlaps"):
        load_scenario("follow_person", ["robot.start=[4.0, 3.0]"])


def test_a_world_section_the_file_lacks_can_be_set():
    assert "lighting" not in load_scenario("follow_person").world
    s = load_scenario("follow_person", ["lighting.ambient=0.3"])
    assert s.world["lighting"] == {"ambient": 0.3}
    with pytest.raises(ScenarioError, match="did you mean 'ambient'"):
        load_scenario("follow_person", ["lighting.ambiant=0.3"])


@pytest.mark.parametrize("key", ["lighting.ambient", "lighting.intensity"])
def test_a_light_level_the_keyframes_would_replace_is_refused(key):
    # `lighting` dims by its keyframes: a constant level set over them changed nothing.
    with pytest.raises(ScenarioError, match=rf"^{key} is not used: the scenario's lighting\.keyf"):
        load_scenario("lighting", [f"{key}=0.1"])
    with pytest.raises(ScenarioError, match=rf"^{key} is not used"):
        load_scenario("follow_person", ["lighting.keyframes=[[0, 0.5, 0.5]]", f"{key}=0.1"])
    # With the keyframes gone (in either order) the level is the light.
    for overrides in (
        ["lighting.keyframes=[]", f"{key}=0.1"],
        [f"{key}=0.1", "lighting.keyframes=[]"],
    ):
        lighting = load_scenario("lighting", overrides).world["lighting"]
        assert lighting[key.split(".")[1]] == 0.1 and lighting["keyframes"] == []


def test_a_camera_value_the_other_sensor_path_reads_is_refused():
    # noise_std is the plain path's, [camera.ov7670] the sensor model's: set on the other
    # path, it changed nothing.
    with pytest.raises(
        ScenarioError, match=r'^camera\.noise_std is not used: with camera\.sensor = "ov7670"'
    ):
        load_scenario("follow_person", ["camera.sensor=ov7670", "camera.noise_std=8"])
    with pytest.raises(
        ScenarioError, match=r'^camera\.ov7670\.max_gain is not used: camera\.sensor is "plain"'
    ):
        load_scenario("follow_person", ["camera.ov7670.max_gain=2"])
    assert load_scenario("follow_person", ["camera.noise_std=8"]).camera.noise_std == 8
    s = load_scenario("follow_person", ["camera.ov7670.max_gain=2", "camera.sensor=ov7670"])
    assert s.camera.sensor == "ov7670" and s.camera.ov7670.max_gain == 2


# -- limits, names, types and the camera's geometry (issue 11) --------------------------------


def test_the_largest_runs_allowed_load():
    # A day at the default rates (20.7 million steps, 2.6 million frames).
    assert load_scenario("follow_person", ["sim.duration=86400"]).sim.duration == 86400
    # The finest physics step for a second (100,000 steps); 1000 fps with a step per frame
    # for 10,000 s: exactly the frame limit, and exactly the step limit.
    assert load_scenario("follow_person", ["sim.duration=1", "sim.physics_dt=1e-5"])
    assert load_scenario(
        "follow_person", ["sim.duration=10000", "camera.fps=1000", "sim.physics_dt=0.001"]
    )
    assert load_scenario("follow_person", ["sim.duration=1000", "sim.physics_dt=1e-5"])
    with pytest.raises(ScenarioError, match="100000001 physics steps; the limit is 100000000"):
        load_scenario("follow_person", ["sim.duration=1000.00001", "sim.physics_dt=1e-5"])
    with pytest.raises(ScenarioError, match="10000001 camera frames; the limit is 10000000"):
        load_scenario(
            "follow_person", ["sim.duration=10000.001", "camera.fps=1000", "sim.physics_dt=0.001"]
        )
    # The design's largest and smallest resolutions (width - 2 * margin_x divisible by 8).
    assert load_scenario("follow_person", ['camera.resolution="4000x4096"']).params.width == 4000
    s = load_scenario("follow_person", ['camera.resolution="16x2"', "design.margin_x=0"])
    assert (s.params.width, s.params.height) == (16, 2)


@pytest.mark.parametrize("width,height", [(15, 120), (4097, 120), (160, 1), (160, 4097)])
def test_resolution_limits_are_the_designs(width, height):
    from fpga_robotics.hw.params import FollowTargetParams

    with pytest.raises(ScenarioError, match=r"width must be 16\.\.4096 and the height 2\.\.4096"):
        load_scenario("follow_person", [f'camera.resolution="{width}x{height}"'])
    with pytest.raises(ValueError):
        FollowTargetParams(width=width, height=height)


def test_a_file_name_that_is_no_scenario_name_is_made_one(tmp_path):
    assert load_scenario(write(tmp_path, "", "my room (v2).toml")).name == "my_room__v2_"
    assert load_scenario(write(tmp_path, "", ".hidden.toml")).name == "hidden"
    assert load_scenario(write(tmp_path, "", "a" * 80 + ".toml")).name == "a" * 64


def test_names_that_are_safe_file_names_are_accepted():
    for name in ("x", "a" * 64, "run-2.v1", "_tmp"):
        assert load_scenario("follow_person", [f'name="{name}"']).name == name
    for name in ("a/b", "..", ".x", "-x", "a b", "a" * 65, "caf\u00e9", "a\\b", ""):
        with pytest.raises(ScenarioError, match="cannot be a file name"):
            load_scenario("follow_person", [f'name="{name}"'])


def test_array_items_can_be_set_as_the_world_names_them():
    s = load_scenario(
        "follow_person",
        ["people[0].shirt_color=[0.1, 0.8, 0.1]", "people[0].waypoints[1]=[5.0, 4.0]"],
    )
    person = s.world["people"][0]
    assert person["shirt_color"] == [0.1, 0.8, 0.1]
    assert person["waypoints"][1] == [5.0, 4.0]
    assert s.overrides[0] == "people[0].shirt_color=[0.1, 0.8, 0.1]"
    with pytest.raises(ScenarioError, match=r"unknown key 'people\[2\].speed': people is a list"):
        load_scenario("follow_person", ["people[2].speed=1"])


def test_a_whole_table_can_be_set_and_its_other_keys_take_their_defaults():
    s = load_scenario("follow_person", ["camera={fps = 15.0}"])
    assert s.camera.fps == 15.0
    assert s.camera.noise_std == 0.0  # the default, not the file's 2.0
    assert (s.camera.width, s.camera.height, s.camera.hfov) == (160, 120, 1.047)
    with pytest.raises(ScenarioError, match=r"unknown key camera\.fsp"):
        load_scenario("follow_person", ["camera={fsp = 15.0}"])


@pytest.mark.parametrize(
    "item,message",
    [
        (
            "design.base_dps=fast",
            (
                "design.base_dps must be an array of 8 integers (wheel DPS per "
                "proximity level 0..7), got 'fast'"
            ),
        ),
        ("design.base_dps=[0, 1, 2, 3, 4, 5, 6, 7.5]", "design.base_dps must be an array of 8"),
        (
            "design.proximity_thresholds=5",
            (
                "design.proximity_thresholds must be an array of 7 "
                "integers (pixel counts of levels 1..7), got 5"
            ),
        ),
        (
            "design.proximity_thresholds=[7, 6, 5, 4, 3, 2, 1]",
            "design.proximity_thresholds must be non-decreasing",
        ),
        ("design.lost_frames=0", "design.lost_frames must be >= 1, got 0"),
        ("design.margin_x=100", "design.margin_x=100 leaves no window in a frame 160 wide"),
        (
            'camera.resolution="4096x4096"',
            ("invalid design parameters with camera.resolution 4096x4096: the window width"),
        ),
        ("design=1", "design must be a table"),
    ],
)
def test_design_values_are_checked_with_their_key(item, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [item])
    assert message in str(info.value)


def renderer_accepts(width, height, hfov, tilt):
    from fpga_robotics.sim.camera.raster import CameraRenderer
    from fpga_robotics.sim.camera.scene import CameraPose, Scene

    try:
        CameraRenderer(width, height, hfov).render(Scene(), CameraPose(0, 0, 0, tilt=tilt))
    except ValueError:
        return False
    return True


def scenario_accepts(width, height, hfov, tilt):
    try:
        load_scenario(
            "follow_person",
            [
                f'camera.resolution="{width}x{height}"',
                f"camera.hfov={hfov!r}",
                f"camera.tilt={tilt!r}",
            ],
        )
    except ScenarioError:
        return False
    return True


@pytest.mark.parametrize(
    "width,height,hfov", [(160, 120, 1.047), (320, 240, 2.0), (40, 160, 1.0), (160, 120, 3.1)]
)
def test_the_scenario_accepts_the_tilts_the_renderer_draws(width, height, hfov):
    from fpga_robotics.sim.camera.raster import max_tilt

    limit = max_tilt(width, height, hfov)
    for tilt in (0.0, limit * 0.999, -limit * 0.999, limit + 1e-4, -limit - 1e-4, 1.5707963):
        assert scenario_accepts(width, height, hfov, tilt) == renderer_accepts(
            width, height, hfov, tilt
        ), tilt


def test_the_printed_tilt_limit_can_be_used():
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", ["camera.tilt=1.5"])
    limit = float(str(info.value).split("at most ")[1].split()[0])
    assert load_scenario("follow_person", [f"camera.tilt={limit!r}"]).camera.tilt == limit
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", ["robot.camera_tilt_deg=80"])
    limit = float(str(info.value).split("at most ")[1].split()[0])
    assert 65 < limit < 66
    load_scenario("follow_person", [f"robot.camera_tilt_deg={limit!r}"])


def test_the_tilt_leaves_room_for_the_steepest_slope():
    # ramp: a 9 degree ramp; at 160x120, hfov 1.047 the renderer draws |tilt| <= 65.44 deg, so
    # a robot facing up or down the ramp pitches by 9 more and the mount may tilt 56.44.
    with pytest.raises(ScenarioError) as info:
        load_scenario("ramp", ["robot.camera_tilt_deg=62"])
    message = str(info.value)
    assert "|robot.camera_tilt_deg| must be at most 56.44 deg" in message
    assert "the 9 deg slope of room.terrain 'ramp'" in message
    with pytest.raises(ScenarioError, match=r"\|camera.tilt\| must be at most 0.9851 rad"):
        load_scenario("ramp", ["camera.tilt=-1.0"])
    with pytest.raises(ScenarioError, match="camera.hfov must be at most 2.8747 rad"):
        load_scenario("ramp", ["camera.hfov=3.0"])  # drawn on the level: max_hfov 3.1116
    load_scenario("follow_person", ["robot.camera_tilt_deg=62"])  # no slope: 65.44
    # The limit holds on the ramp itself: standing on it facing uphill, the camera pitches
    # up by the full 9 degrees, and the frames render.
    scenario = load_scenario(
        "ramp", ["robot.camera_tilt_deg=56.44", "robot.start=[4.0, 3.0]", "sim.duration=0.1"]
    )
    poses = []
    run_scenario(scenario, backend="model", on_frame=lambda r: poses.append(r.camera_pose))
    assert poses[0].tilt == pytest.approx(math.radians(56.44 + 9))


def test_the_camera_must_be_below_the_ceiling():
    s = load_scenario("follow_person", ["camera.mount_height=2.4"])
    assert s.camera.mount_height == 2.4
    for item in ("camera.mount_height=2.5", "camera.mount_height=0"):
        with pytest.raises(ScenarioError, match="camera.mount_height must be"):
            load_scenario("follow_person", [item])
    s = load_scenario("follow_person", ["room.height=3.5", "camera.mount_height=3"])
    assert s.camera.mount_height == 3.0


def test_scenario_paths_that_are_not_files(tmp_path, monkeypatch):
    with pytest.raises(ScenarioError, match="is a folder"):
        load_scenario(tmp_path)
    with pytest.raises(ScenarioError, match="is not a regular file"):
        load_scenario("/dev/null")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(
        ScenarioError, match="for the shipped scenario give its name: --scenario lost_target"
    ):
        load_scenario("lost_target.toml")
    (tmp_path / "lost_target.toml").write_text('description = "mine"\n')
    assert load_scenario("lost_target.toml").description == "mine"  # a local file wins
    (tmp_path / "divider").mkdir()  # a folder named like a shipped scenario does not hide it
    assert load_scenario("divider").name == "divider"
    (tmp_path / "mine").mkdir()
    with pytest.raises(ScenarioError, match="'mine' is a folder"):
        load_scenario("mine")
    big = write(tmp_path, "# " + "x" * (1 << 20) + "\n", "big.toml")
    with pytest.raises(ScenarioError, match="a scenario is at most 1048576 bytes"):
        load_scenario(big)


@pytest.mark.parametrize(
    "item,message",
    [
        (
            "sim.duration=1979-05-27",
            (
                "sim.duration must be a finite number in s, > 0 and <= 86400, "
                "got datetime.date(1979, 5, 27)"
            ),
        ),
        (
            "camera.noise_std=nan",
            ("camera.noise_std must be a finite number in 8-bit levels, >= 0 and <= 64, got nan"),
        ),
        (
            "camera.fps=inf",
            ("camera.fps must be a finite number in frames/s, >= 0.1 and <= 1000, got inf"),
        ),
        ("camera.noise_std=65", "camera.noise_std must be <= 64 (8-bit levels), got 65.0"),
        (
            "sim.physics_dt=0.1",
            (
                "sim.physics_dt 0.1 s is longer than a camera frame period (1 / camera.fps "
                "30 = 0.0333333 s); a physics step must be at most one frame: set "
                "sim.physics_dt to 0.0333333 or less, or lower camera.fps"
            ),
        ),
        (  # the default step (1/240 s) against a faster camera: both keys named
            "camera.fps=1000",
            (
                "sim.physics_dt 0.00416667 s is longer than a camera frame period (1 / "
                "camera.fps 1000 = 0.001 s); a physics step must be at most one frame: set "
                "sim.physics_dt to 0.001 or less, or lower camera.fps"
            ),
        ),
        ("sim.physics_dt=1e-6", "sim.physics_dt must be >= 1e-05 s, got 1e-06"),
    ],
)
def test_number_messages_give_the_unit_and_the_range(item, message):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [item])
    assert str(info.value) == message


def test_with_overrides_checks_the_same():
    s = load_scenario("follow_person")
    with pytest.raises(ScenarioError, match="camera must be a table"):
        s.with_overrides(["camera=5"])
    with pytest.raises(ScenarioError, match="one day"):
        s.with_overrides(["sim.duration=1e9"])


def test_an_array_the_scenario_leaves_out_is_set_whole_then_by_index():
    s = load_scenario(
        "follow_person", ["room.furniture=[{center = [4, 3]}]", "room.furniture.0.height=1"]
    )
    assert s.world["room"]["furniture"] == [{"center": [4, 3], "height": 1}]


@pytest.mark.parametrize("name", ["approach", "slippery"])
def test_a_robot_that_stands_still_fails_a_scenario_that_asks_it_to_move(name):
    # FollowTarget with every speed 0 sees the person and never moves: approach (a person
    # standing 2 m ahead) and slippery (a person walking away over a wet strip) passed it on
    # their collision, distance and tracking checks alone.
    still = ["design.base_dps=[0,0,0,0,0,0,0,0]", "design.kp_num=0", "design.search_dps=0"]
    r = run_scenario(load_scenario(name, still), backend="model")
    assert r.summary["path_length_m"] == 0.0
    by = {c["name"]: c for c in r.summary["checks"]}
    assert by["mean_distance_max_m"]["status"] == "fail", by["mean_distance_max_m"]["text"]
    # The mean distance, from the trajectory: the robot's centre to the person's, every frame.
    t = r.trajectory
    mean = np.hypot(t["target_x"] - t["x"], t["target_y"] - t["y"]).mean()
    assert by["mean_distance_max_m"]["value"] == pytest.approx(mean)
    assert r.summary["verdict"] == "fail"
