"""World configuration: defaults, and a clear WorldConfigError naming the key for bad input."""

import math
import pathlib
import re
import tomllib

import pytest

from fpga_robotics.sim.world import GOPIGO3, TURTLEBOT2, World, WorldConfigError, parse_world_config


def test_empty_config_gives_the_default_world():
    cfg = parse_world_config({})
    assert (cfg.room.width, cfg.room.depth, cfg.room.height) == (8.0, 6.0, 2.5)
    assert cfg.room.furniture == ()
    assert cfg.robot.spec == TURTLEBOT2
    assert cfg.robot.start == (1.5, 3.0) and cfg.robot.heading == 0.0
    assert len(cfg.people) == 1 and cfg.people[0].target
    assert cfg.lighting.keyframes == ()
    assert parse_world_config(None) == cfg


def test_model_preset_and_overrides():
    cfg = parse_world_config({"robot": {"model": "gopigo3", "mass": 1.2, "heading_deg": 90}})
    spec = cfg.robot.spec
    assert spec.name == "gopigo3" and spec.mass == 1.2
    assert spec.wheel_radius == GOPIGO3.wheel_radius
    assert spec.traction_force == GOPIGO3.traction_force  # mass does not buy traction
    assert cfg.robot.heading == pytest.approx(math.pi / 2)
    # traction_torque follows traction_force unless given.
    spec = parse_world_config({"robot": {"traction_force": 4.0}}).robot.spec
    assert spec.traction_torque == pytest.approx(4.0 * 0.230 / 2)


def test_default_people_scale_with_the_room():
    cfg = parse_world_config({"room": {"width": 4.0, "depth": 3.0}})
    assert cfg.robot.start == (1.5, 1.5)
    assert cfg.people[0].waypoints[0] == (2.0, 1.5)


BAD = [
    ({"robot": {"mass": -1}}, "robot.mass must be >= 0.05, got -1"),
    ({"robot": {"mass": 1e-300}}, "robot.mass must be >= 0.05, got 1e-300"),
    ({"robot": {"mass": "heavy"}}, "robot.mass must be a number in kg >= 0.05"),
    # A radius of 1e-300 m gave pymunk a zero moment of inertia (an AssertionError).
    ({"robot": {"body_radius": 1e-300}}, "robot.body_radius must be >= 0.02, got 1e-300"),
    ({"robot": {"wheel_separation": 1e-300}}, "robot.wheel_separation must be >= 0.02"),
    ({"robot": {"wheel_radius": 0.001}}, "robot.wheel_radius must be >= 0.005"),
    # The renderer draws from between the floor and the ceiling only.
    (
        {"robot": {"camera_height": 3}},
        "robot.camera_height must be below the ceiling (room.height = 2.5 m), got 3",
    ),
    (
        {"room": {"height": 0.25}},
        "robot.camera_height must be below the ceiling (room.height = 0.25 m), got 0.3",
    ),
    ({"robot": {"camera_height": 2.5}}, "robot.camera_height must be below the ceiling"),
    # Nothing stands taller than the room: the two renderers would disagree about it.
    (
        {"room": {"height": 1.0}, "people": [{"waypoints": [[4, 3]]}]},
        "people[0].height must be at most the ceiling's (room.height = 1 m), got 1.75",
    ),
    (
        {"room": {"height": 0.5, "furniture": [{"center": [4, 3], "height": 1.5}]}},
        "room.furniture[0].height must be at most the ceiling's (room.height = 0.5 m), got 1.5",
    ),
    ({"robot": {"camera_tilt_deg": 90}}, "robot.camera_tilt_deg must be <= 85, got 90"),
    ({"robot": {"mass": True}}, "robot.mass must be a number"),
    ({"robot": {"mass": float("nan")}}, "robot.mass must be a number"),
    ({"robot": {"mas": 5}}, "robot.mas is not a known key (did you mean 'mass'?)"),
    ({"robot": {"model": "roomba"}}, "robot.model must be one of 'turtlebot2', 'gopigo3'"),
    ({"robot": {"start": [1, 2, 3]}}, "robot.start must be a point [x, y]"),
    ({"robot": {"start": [0.1, 3]}}, "robot.start [0.1, 3] puts the robot"),
    ({"robot": {"max_wheel_dps": 0}}, "robot.max_wheel_dps must be > 0"),
    ({"robot": "fast"}, "robot must be a table"),
    ({"rooom": {}}, "rooom is not a world section (did you mean 'room'?)"),
    ({"room": {"width": 0}}, "room.width must be > 0.5"),
    ({"room": {"wall_color": [1.2, 0, 0]}}, "room.wall_color[0] must be <= 1, got 1.2"),
    ({"room": {"wall_color": "red"}}, "room.wall_color must be a colour [r, g, b]"),
    ({"room": {"furniture": {"center": [1, 1]}}}, "room.furniture must be an array of tables"),
    ({"room": {"furniture": [{"size": [1, 1]}]}}, "room.furniture[0].center is required"),
    (
        {"room": {"furniture": [{"center": [1, 1], "type": "sofa"}]}},
        "room.furniture[0].type must be one of 'box', 'divider', got 'sofa'",
    ),
    (
        {"room": {"furniture": [{"center": [1, 1], "size": [1]}]}},
        "room.furniture[0].size must be [length, width]",
    ),
    (
        {"room": {"furniture": [{"center": [1, 1], "size": [1, -2]}]}},
        "room.furniture[0].size[1] must be >= 0.01",
    ),
    # Corners 1e-300 apart were one point: a wall of zero length for the renderer.
    (
        {"room": {"furniture": [{"center": [1, 1], "size": [1e-300, 1e-300]}]}},
        "room.furniture[0].size[0] must be >= 0.01, got 1e-300",
    ),
    ({"room": {"furniture": [{"center": [9, 1]}]}}, "room.furniture[0].center [9, 1] is outside"),
    (
        {"room": {"furniture": [{"center": [1, 1], "colour": [0, 0, 0]}]}},
        "room.furniture[0].colour is not a known key (did you mean 'color'?)",
    ),
    (
        {"room": {"furniture": [{"center": [1, 1]}, {"center": [2, 2], "name": "furniture0"}]}},
        "room.furniture[1].name 'furniture0' is used twice",
    ),
    ({"people": {"waypoints": [[1, 1]]}}, "people must be an array of tables"),
    ({"people": [{}]}, "people[0].waypoints is required"),
    ({"people": [{"waypoints": []}]}, "people[0].waypoints must be a non-empty array"),
    ({"people": [{"waypoints": [[1, 1], [2]]}]}, "people[0].waypoints[1] must be a point [x, y]"),
    ({"people": [{"waypoints": [[1, 1], [20, 2]]}]}, "people[0].waypoints[1] [20, 2] puts the"),
    ({"people": [{"waypoints": [[1, 1]], "speed": 0}]}, "people[0].speed must be > 0, got 0"),
    (
        {"people": [{"waypoints": [[1, 1], [2, 2]], "pause": [1, 2, 3]}]},
        "people[0].pause must be one number or one per waypoint (2), got 3 values",
    ),
    ({"people": [{"waypoints": [[1, 1]], "pause": [-1]}]}, "people[0].pause[0] must be >= 0"),
    (
        {"people": [{"waypoints": [[1, 1]], "radius": 1e-300}]},
        "people[0].radius must be >= 0.05, got 1e-300",
    ),
    (
        {"people": [{"waypoints": [[1, 1]], "yield_gap": -1}]},
        "people[0].yield_gap must be >= 0, got -1",
    ),
    (
        {"people": [{"waypoints": [[1, 1]], "start_delay": 1e300}]},
        "people[0].start_delay must be <= 86400, got 1e+300",
    ),
    ({"people": [{"waypoints": [[1, 1]], "loop": "yes"}]}, "people[0].loop must be true or false"),
    (
        {"people": [{"waypoints": [[1, 1]], "shirt_colour": [1, 0, 0]}]},
        "people[0].shirt_colour is not a known key (did you mean 'shirt_color'?)",
    ),
    (
        {"people": [{"waypoints": [[1, 1]]}, {"waypoints": [[2, 2]], "target": True}]},
        "people[1].target: only one person can be the target",
    ),
    (
        {"people": [{"waypoints": [[1, 1]], "name": "a"}, {"waypoints": [[2, 2]], "name": "a"}]},
        "people[1].name 'a' is used twice",
    ),
    ({"lighting": {"ambient": 3}}, "lighting.ambient must be <= 2, got 3"),
    (
        {"lighting": {"direction": [0, 0, 0]}},
        "lighting.direction must have a length of at least 0.001, got [0, 0, 0]",
    ),
    # Too small or too large to normalise: the renderer refused them at the first frame.
    (
        {"lighting": {"direction": [1e-300, 0, 0]}},
        "lighting.direction must have a length of at least 0.001, got [1e-300, 0, 0]",
    ),
    (
        {"lighting": {"direction": [1e300, 1e300, 1]}},
        "lighting.direction[0] must be <= 1000, got 1e+300",
    ),
    (
        {"lighting": {"keyframes": [[1e300, 1, 1]]}},
        "lighting.keyframes[0][0] (t) must be <= 86400, got 1e+300",
    ),
    (
        {"lighting": {"interpolation": "cubic"}},
        "lighting.interpolation must be one of 'linear', 'step', got 'cubic'",
    ),
    (
        {"lighting": {"keyframes": [[0, 1, 1], [1, 1]]}},
        "lighting.keyframes[1] must be [t, ambient, intensity]",
    ),
    (
        {"lighting": {"keyframes": [[5, 1, 1], [4, 1, 1]]}},
        "lighting.keyframes[1][0] (t) must not be earlier than the previous keyframe's (5 s)",
    ),
    ({"lighting": {"keyframes": [[0, 1, -1]]}}, "lighting.keyframes[0][2] (intensity) must be"),
    ("room", "the world configuration must be a table"),
]


@pytest.mark.parametrize("cfg, message", BAD, ids=[m[:40] for _, m in BAD])
def test_bad_values_name_the_key(cfg, message):
    with pytest.raises(WorldConfigError) as info:
        World.from_config(cfg, seed=0)
    assert message in str(info.value)
    assert isinstance(info.value, ValueError)


def test_robot_starting_inside_furniture_is_an_error():
    cfg = {"room": {"furniture": [{"name": "desk", "center": [1.5, 3.0]}]}}
    with pytest.raises(WorldConfigError, match="robot.start .* overlaps the furniture 'desk'"):
        World.from_config(cfg, seed=0)


def test_robot_starting_on_a_person_is_an_error():
    cfg = {"people": [{"name": "ann", "waypoints": [[1.7, 3.0], [5, 3]]}]}
    with pytest.raises(WorldConfigError, match="overlaps the person 'ann'"):
        World.from_config(cfg, seed=0)


def test_an_error_names_the_default_start_and_what_to_set():
    """The user who wrote no robot.start is told it is the default and which key to set."""
    desk = {"room": {"furniture": [{"name": "desk", "center": [1.5, 3.0]}]}}
    default = r"the default robot\.start \(the scenario sets none\) \[1\.5, 3\] overlaps"
    with pytest.raises(WorldConfigError, match=default + " the furniture 'desk'; set robot.start"):
        World.from_config(desk, seed=0)
    # Written by the user: named as written, no advice.
    desk["robot"] = {"start": [1.5, 3.0]}
    with pytest.raises(WorldConfigError, match=r"^robot\.start \[1\.5, 3\] overlaps[^;]*$"):
        World.from_config(desk, seed=0)
    # A robot too wide to stand beside the default person (0.5 m apart at any width).
    with pytest.raises(
        WorldConfigError,
        match=r"default robot\.start .*\[1\.5, 3\] overlaps the person 'target' \(at \[2, 3\]\); "
        "set robot.start",
    ):
        World.from_config({"room": {"width": 4.0}, "robot": {"body_radius": 0.4}}, seed=0)
    with pytest.raises(
        WorldConfigError,
        match=r"default robot\.start .* \[0\.1, 3\] puts the robot .* set robot\.start$",
    ):
        World.from_config({"room": {"width": 1.2}}, seed=0)
    with pytest.raises(WorldConfigError, match=r"^the default person \(the scenario has no"):
        World.from_config({"room": {"width": 8.0, "depth": 0.7}}, seed=0)


@pytest.mark.parametrize("width", [1.4, 2.0, 3.0, 3.7, 3.9, 5.0, 8.0, 30.0])
def test_the_default_placement_fits_a_narrow_room(width):
    """The default robot starts 1.5 m in, or half a metre short of mid-room in a room narrower
    than 4 m; the default person stands mid-room ahead of it: clear of each other (their bodies
    touch 0.377 m apart) in any room 1.4 m wide or more."""
    world = World.from_config({"room": {"width": width, "depth": 8.0}}, seed=0)
    x, y = world.config.robot.start
    assert (x, y) == (min(1.5, width / 2 - 0.5), 4.0)
    (person,) = world.config.people
    px, py = person.waypoints[0]
    assert py == y and px - x >= world.config.robot.spec.body_radius + person.radius


def test_seed_must_be_a_non_negative_integer():
    with pytest.raises(ValueError, match="seed"):
        World.from_config({}, seed=-1)
    with pytest.raises(ValueError, match="seed"):
        World.from_config({}, seed=1.5)


def test_the_documented_examples_load():
    doc = pathlib.Path(__file__).parents[1] / "docs" / "scenarios.md"
    blocks = re.findall(r"```toml\n(.*?)```", doc.read_text(), re.DOTALL)
    assert len(blocks) >= 2
    for block in blocks:
        world = World.from_config(tomllib.loads(block), seed=0)
        world.step(0.1)
