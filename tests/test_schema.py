"""The declarative key schema: one pydantic model per scenario table, one adapter from a
ValidationError to the one-line message, the connector kinds' key models, and the key tables
of docs/scenarios.md against the models."""

import dataclasses
import re
from pathlib import Path
from typing import Annotated, ClassVar

import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.loop.connectors.base import (
    CONNECTORS,
    Connector,
    ConnectorError,
    ConnectorKeys,
    MountKeys,
    Pin,
    register,
)
from fpga_robotics.scenario.connectors import parse_connectors
from fpga_robotics.scenario.load import DEFAULTS, ScenarioError, load_scenario
from fpga_robotics.scenario.schema import (
    CameraKeys,
    ColorKeys,
    LampKeys,
    SimKeys,
    TopKeys,
    design_keys,
    ov7670_keys,
)
from fpga_robotics.sim.camera.sensor import PARAMS as SENSOR_PARAMS
from fpga_robotics.sim.world.keys import WORLD_KEY_MODELS
from fpga_robotics.sim.world.schema import (
    Flag,
    KeyModel,
    Number,
    Tables,
    Text,
    Vector,
    validate,
)

DOCS = Path(__file__).resolve().parent.parent / "docs" / "scenarios.md"


class _Item(KeyModel):
    x: Number(ge=0, le=2, unit="m") = 0.0
    on: Flag() = True


class _Table(KeyModel):
    kind: Text(choices=("a", "b")) = "a"
    where: Vector(2, "a point [x, y] in m") = (0, 0)
    items: Annotated[list[_Item], *Tables("an array of tables ([[t.items]])")] = ()


class _Bad(ValueError):
    pass


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"items": [{}, {"x": 3}]}, "t.items[1].x must be <= 2, got 3"),
        ({"items": [{"x": -1}]}, "t.items[0].x must be >= 0, got -1"),
        ({"items": [{"x": "far"}]}, "t.items[0].x must be a number in m >= 0 and <= 2, got 'far'"),
        ({"items": [{"x": float("inf")}]}, "t.items[0].x must be a number in m >= 0"),
        ({"items": [{"on": 1}]}, "t.items[0].on must be true or false, got 1 (int)"),
        ({"items": {"x": 1}}, "t.items must be an array of tables ([[t.items]]), got a table"),
        ({"items": [3]}, "t.items[0] must be a table, got 3 (int)"),
        ({"where": [1, "y"]}, "t.where[1] must be a number"),
        ({"where": [1]}, "t.where must be a point [x, y] in m, got [1] (array)"),
        ({"kind": "c"}, "t.kind must be one of 'a', 'b', got 'c'"),
        ({"knd": "a"}, "t.knd is not a known key (did you mean 'kind'?); known keys: kind, "),
        ({"items": [{"xx": 1}]}, "t.items[0].xx is not a known key (did you mean 'x'?)"),
        ("a string", "t must be a table, got 'a string' (str)"),
    ],
)
def test_the_adapter_names_the_key_path_the_value_and_the_range(table, message):
    with pytest.raises(_Bad) as info:
        validate(_Table, table, "t", _Bad)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_a_valid_table_gives_its_values_and_defaults():
    keys = validate(_Table, {"items": [{"x": 1}, {"on": False}], "where": [1, 2]}, "t", _Bad)
    assert keys.kind == "a"
    assert keys.where == (1.0, 2.0)
    assert [(i.x, i.on) for i in keys.items] == [(1.0, True), (0.0, False)]
    assert isinstance(keys.items[0].x, float)  # an int in the file is a float


def test_a_wrong_value_is_reported_before_a_typo():
    with pytest.raises(_Bad, match=r"t\.kind must be one of"):
        validate(_Table, {"kindd": 1, "kind": "z"}, "t", _Bad)


class _ToyKeys(ConnectorKeys):
    gain: Number(gt=0, le=2, style="bounds") = 1.0
    invert: Flag(style="scenario") = False


class _Toy(Connector):
    kind = "toy_schema_sensor"
    pins: ClassVar[dict] = {"out": Pin("in")}
    keys = _ToyKeys


@pytest.fixture
def toy_kind():
    register(_Toy)
    try:
        yield
    finally:
        del CONNECTORS[_Toy.kind]


def test_a_connector_kind_declares_its_keys_as_a_model(toy_kind):
    (spec,) = parse_connectors(
        {"sensors": [{"kind": "toy_schema_sensor", "gain": 1.5, "forward": 0.1, "yaw_deg": 90}]}
    )
    assert (spec.params.gain, spec.params.invert) == (1.5, False)
    assert spec.mount.forward == 0.1
    assert spec.mount.yaw == pytest.approx(3.141592653589793 / 2)


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ({"gain": 0}, "robot.sensors[0].gain must be a number > 0 and <= 2, got 0"),
        ({"invert": "yes"}, "robot.sensors[0].invert must be true or false, got 'yes'"),
        (
            {"gian": 1},
            (
                "robot.sensors[0]: unknown key 'gian' for a 'toy_schema_sensor' connector; its "
                "keys: gain, invert (and the mount: forward, left, height, yaw_deg)"
            ),
        ),
        ({"height": 4}, "robot.sensors[0].height must be a number in m >= 0 and <= 3, got 4"),
    ],
)
def test_a_connector_kinds_keys_are_checked_by_its_model(toy_kind, table, message):
    with pytest.raises(ConnectorError) as info:
        parse_connectors({"sensors": [{"kind": "toy_schema_sensor", **table}]})
    assert str(info.value) == message


def test_the_defaults_come_from_the_models():
    assert DEFAULTS["sim"]["duration"] == 20.0
    assert DEFAULTS["sim"]["physics_dt"] == 1 / 240
    assert DEFAULTS["sim"]["actuation_delay"] is None
    assert DEFAULTS["camera"]["resolution"] == "160x120"
    assert DEFAULTS["camera"]["lamps"] == []
    assert DEFAULTS["camera"]["ov7670"]["aec_window"] == [0x63, 0x75]
    assert DEFAULTS["color"] == {"initial": "red", "changes": []}
    # A loaded scenario's data carries them, as a file that gave them would.
    data = load_scenario("follow_person").data
    assert data["camera"]["shadow_size"] == 256 and data["sim"]["timing"] == "auto"


def test_the_registry_built_sections_follow_their_registries():
    assert ov7670_keys().key_names() == list(SENSOR_PARAMS)
    given = {f.name for f in dataclasses.fields(FollowTargetParams) if f.init}
    assert given - {"width", "height"} <= set(design_keys().key_names())


def test_a_new_key_in_a_model_is_a_key_of_the_scenario():
    """A key declared in a model is accepted with its range, nothing else to edit."""
    with pytest.raises(ScenarioError, match=r"camera\.yaw_offset_deg must be <= 45 deg, got 50"):
        load_scenario("follow_person", ["camera.yaw_offset_deg=50"])
    with pytest.raises(ScenarioError, match=r"close matches: camera\.yaw_offset_deg"):
        load_scenario("follow_person", ["camera.yaw_ofset_deg=5"])


# The key tables of docs/scenarios.md -------------------------------------------------------

#: The heading's table (by the table path it names) -> the model of its keys.
DOC_TABLES = {
    **WORLD_KEY_MODELS,
    "robot.sensors": MountKeys,
    "sim": SimKeys,
    "camera": CameraKeys,
    "camera.lamps": LampKeys,
    "color": ColorKeys,
}
#: The table under "The keys outside any section".
TOP_TABLE = "The keys outside any section"


def doc_tables(text=None):
    """``{table path: [keys of its first table]}`` of docs/scenarios.md: a heading naming
    ``[path]`` or ``[[path]]`` owns the first key table after it."""
    text = DOCS.read_text() if text is None else text
    out, current = {}, None
    for line in text.splitlines():
        heading = re.match(r"#+ .*?`\[\[?([\w.]+)\]\]?`", line)
        if heading:
            current = heading.group(1)
            continue
        if line.startswith(TOP_TABLE):
            current = ""
        if current is not None and line.startswith("| `"):
            first = line.split("|")[1]
            out.setdefault(current, []).extend(re.findall(r"`(\w+)`", first))
        elif current is not None and current in out and not line.startswith("|"):
            current = None  # the table has ended
    return out


def test_every_schema_key_is_in_the_docs_tables_and_every_documented_key_in_the_schema():
    tables = doc_tables()
    for path, model in DOC_TABLES.items():
        assert path in tables, f"docs/scenarios.md has no key table for [{path}]"
        documented = set(tables[path])
        declared = set(model.key_names())
        assert declared - documented == set(), f"[{path}]: keys missing from docs/scenarios.md"
        assert documented - declared == set(), f"[{path}]: documented keys not in the schema"
    assert set(tables[""]) == set(TopKeys.key_names())


def test_the_docs_table_reader_sees_a_missing_key():
    text = "## `[sim]`\n\n| key | type |\n|---|---|\n| `duration` | number |\n\nprose\n"
    assert doc_tables(text) == {"sim": ["duration"]}
