"""The shipped Foxglove layout: up to date with its builder, showing only topics a run
publishes, and its buttons and teleop pad send what the live server turns into the intended
control inputs (issue 16)."""

import json
from importlib.resources import files

from fpga_robotics.ros.controls import TELEOP_SPEED, check_input
from fpga_robotics.ros.foxglove_live import CONTROL_TOPICS, control_input, layout_path
from fpga_robotics.ros.layout import layout_json
from fpga_robotics.ros.messages import TOPICS


def _panels(node):
    if node.get("type") == "panel":
        yield node
    for item in node.get("items", []):
        yield from _panels(item["content"])


def test_shipped_layout_is_the_builders():
    shipped = files("fpga_robotics.ros").joinpath("foxglove_layout.json").read_text()
    assert shipped == layout_json()
    assert layout_path().read_text() == shipped


def test_layout_shows_published_topics_and_sends_controls():
    panels = list(_panels(json.loads(layout_json())["content"]))
    kinds = {p["panelType"] for p in panels}
    assert {"Image", "ThreeDee", "Plot", "Teleop", "Publish"} <= kinds
    for p in panels:
        cfg = p["config"]
        if p["panelType"] == "Image":
            assert cfg["imageMode"]["imageTopic"] in TOPICS
        if p["panelType"] == "Plot":
            for series in cfg["paths"]:
                assert series["value"].split(".")[0] in TOPICS
        if p["panelType"] == "ThreeDee":
            assert set(cfg["topics"]) <= set(TOPICS)
    # Each publish button: a message the server turns into a valid input.
    sent = []
    for p in panels:
        if p["panelType"] == "Publish":
            topic = p["config"]["topicName"]
            assert topic in CONTROL_TOPICS
            sent.append(check_input(*control_input(topic, json.loads(p["config"]["value"]))))
    assert ("color", "red") in sent and ("color", "blue") in sent
    assert {("pause", None), ("resume", None), ("step", None)} <= set(sent)
    # The teleop pad: up drives the target +y, right +x, at the terminal's speed.
    teleop = next(p["config"] for p in panels if p["panelType"] == "Teleop")
    assert teleop["topic"] == "/target/cmd_vel"
    for button, expected in (
        ("upButton", [0.0, TELEOP_SPEED]),
        ("rightButton", [TELEOP_SPEED, 0.0]),
        ("downButton", [0.0, -TELEOP_SPEED]),
        ("leftButton", [-TELEOP_SPEED, 0.0]),
    ):
        field, value = teleop[button]["field"], teleop[button]["value"]
        kind, axis = field.split("-")  # what Foxglove's teleop panel sets in the Twist
        twist = {
            "linear": {"x": 0.0, "y": 0.0, "z": 0.0},
            "angular": {"x": 0.0, "y": 0.0, "z": 0.0},
        }
        twist[kind][axis] = value
        assert control_input("/target/cmd_vel", twist) == ("target_velocity", expected)


def _layout_command(*argv):
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-m", "fpga_robotics.ros.layout", *argv],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )


def test_the_rewrite_command_answers_help_and_refuses_arguments_without_writing():
    before = layout_path().stat().st_mtime_ns
    helped = _layout_command("--help")
    assert helped.returncode == 0 and "usage: python -m fpga_robotics.ros.layout" in helped.stdout
    refused = _layout_command("--bogus")
    assert refused.returncode == 2
    assert refused.stderr == (
        "python -m fpga_robotics.ros.layout: error: unrecognized arguments: --bogus\n"
    )
    assert layout_path().stat().st_mtime_ns == before  # neither rewrote the shipped file
