"""Scenario files: loading, defaults, overrides and the errors a user sees."""

import math

import pytest

from fpga_robotics.errors import UsageError
from fpga_robotics.scenario import (
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
    from fpga_robotics import scenario
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


def test_defaults_fill_the_application_sections(tmp_path):
    s = load_scenario(write(tmp_path, MINIMAL))
    assert s.name == "mini" and s.seed == 0
    assert (s.camera.width, s.camera.height, s.camera.fps, s.camera.hfov) == (160, 120, 30.0,
                                                                               1.047)
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
    s = load_scenario(path, [
        "sim.duration=7",            # an int where a float was: a float
        "camera.fps=15",
        "color.initial=green",       # a bare word is a string
        'camera.resolution="320x240"',
        "design.kp_num=2",
        "design.base_dps=[0, 200, 150, 100, 80, 50, -50, -80]",
        "seed=42",
        "checks.max_person_collisions=0",
    ])
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


def test_colour_changes_take_effect_at_their_time(tmp_path):
    s = load_scenario(write(tmp_path, MINIMAL + """
[color]
initial = "red"
changes = [{at = 1.0, color = "green"}, {at = 2.5, color = "none"}]
"""))
    assert [s.color_at(t) for t in (0.0, 0.99, 1.0, 2.0, 2.5, 9.0)] == [
        "red", "red", "green", "green", "none", "none"]


@pytest.mark.parametrize("item,expect", [
    ("design.kp=1", "design.kp_num"),
    ("sim.duratoin=3", "sim.duration"),
    ("camera.fsp=3", "camera.fps"),
    ("checks.acquired_within=3", "checks.acquired_within_s"),
    ("robot.mas=12", "mass"),                # the world names its known keys
    ("people.0.sped=1", "speed"),
])
def test_unknown_keys_are_errors_with_close_matches(item, expect):
    with pytest.raises(ScenarioError) as info:
        load_scenario("follow_person", [item])
    assert item.split("=")[0].split(".")[-1] in str(info.value)
    assert expect in str(info.value)


@pytest.mark.parametrize("item,fragment", [
    ("design.width=320", "camera.resolution"),
    ("people.5.speed=1", "index it with 0..0"),
    ("sim.duration", "KEY=VALUE"),
    ("sim.duration=-1", "sim.duration must be > 0"),
    ("sim.physics_dt=0.5", "sim.physics_dt must be <="),
    ("camera.resolution=abc", "WIDTHxHEIGHT"),
    ("color.initial=purple", "color.initial must be one of"),
    ("design.kp_num=1.5", "kp_num must be an int"),
    ("checks.max_person_collisions=-1", ">= 0"),
    ("robot.mass=-1", "robot.mass"),
])
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
