"""The Foxglove layout shipped for a run's topics (``foxglove_layout.json`` next to this file).

Built with foxglove-sdk's layout types; ``python -m fpga_robotics.ros.layout`` rewrites the
shipped file (a test checks that it is up to date). In Foxglove: Layouts, Import from file.

Left: the camera and the design's filtered frame. Middle: the 3D scene seen from above
(odom frame: the robot's tf, the people as cylinders). Right: the design's outputs and the
commanded twist over time; a teleop pad that drives the target person (``/target/cmd_vel``,
world frame: up = +y, right = +x); buttons for the colour select, pause, resume and step.
"""

import json
import sys

import foxglove.layouts as fl

from .controls import TELEOP_SPEED

__all__ = ["build_layout", "layout_json"]

_COLOR_BUTTONS = (("red", "#d03030"), ("green", "#30a030"), ("blue", "#3050d0"))


def _image(topic, title):
    return fl.ImagePanel(
        title=title,
        config=fl.ImageConfig(
            image_mode=fl.ImageModeConfig(
                color_mode="flat", image_topic=topic, calibration_topic="/camera/camera_info"
            )
        ),
    )


def _publish(topic, datatype, text, value, color=None):
    return fl.PublishPanel(
        title=text,
        config=fl.PublishConfig(
            topic_name=topic,
            datatype=datatype,
            button_text=text,
            button_color=color,
            advanced_view=False,
            value=json.dumps(value),
        ),
    )


def _column(*panels):
    return fl.SplitContainer(
        direction="column", items=[fl.SplitItem(proportion=1, content=p) for p in panels]
    )


def _row(*panels):
    return fl.SplitContainer(
        direction="row", items=[fl.SplitItem(proportion=1, content=p) for p in panels]
    )


def build_layout():
    """The layout as a ``foxglove.layouts.Layout``."""
    scene = fl.ThreeDeePanel(
        title="scene (top-down)",
        config=fl.ThreeDeeConfig(
            fixed_frame="odom",
            follow_tf="base_link",
            follow_mode="follow-position",
            topics={"/people": fl.BaseRendererRosMarkerTopicSettings(visible=True)},
        ),
    )
    outputs = fl.PlotPanel(
        title="design outputs",
        config=fl.PlotConfig(
            paths=[
                fl.PlotSeries(value="/fpga/found.data", label="found"),
                fl.PlotSeries(value="/fpga/proximity.data", label="proximity"),
                fl.PlotSeries(value="/fpga/centroid_leds.data", label="centroid LEDs"),
            ],
            show_legend=True,
        ),
    )
    twist = fl.PlotPanel(
        title="commanded twist",
        config=fl.PlotConfig(
            paths=[
                fl.PlotSeries(value="/cmd_vel.linear.x", label="V m/s"),
                fl.PlotSeries(value="/cmd_vel.angular.z", label="W rad/s"),
                fl.PlotSeries(value="/odom.twist.twist.linear.x", label="measured V m/s"),
            ],
            show_legend=True,
        ),
    )
    teleop = fl.TeleopPanel(
        title="drive the target",
        config=fl.TeleopConfig(
            topic="/target/cmd_vel",
            publish_rate=5,
            up_button=fl.TeleopButton(field="linear-y", value=TELEOP_SPEED),
            down_button=fl.TeleopButton(field="linear-y", value=-TELEOP_SPEED),
            right_button=fl.TeleopButton(field="linear-x", value=TELEOP_SPEED),
            left_button=fl.TeleopButton(field="linear-x", value=-TELEOP_SPEED),
            auto_send_stop_on_release=True,
        ),
    )
    colors = _row(
        *(
            _publish("/fpga/color_select", "std_msgs/String", name, {"data": name}, rgb)
            for name, rgb in _COLOR_BUTTONS
        )
    )
    run = _row(
        _publish("/sim/pause", "std_msgs/Bool", "pause", {"data": True}),
        _publish("/sim/pause", "std_msgs/Bool", "resume", {"data": False}),
        _publish("/sim/step", "std_msgs/Empty", "step", {}),
    )
    return fl.Layout(
        content=fl.SplitContainer(
            direction="row",
            items=[
                fl.SplitItem(
                    proportion=1,
                    content=_column(
                        _image("/camera/image_raw", "camera"),
                        _image("/fpga/filtered/image", "filtered (design)"),
                    ),
                ),
                fl.SplitItem(proportion=1, content=scene),
                fl.SplitItem(
                    proportion=1,
                    content=fl.SplitContainer(
                        direction="column",
                        items=[
                            fl.SplitItem(proportion=2, content=outputs),
                            fl.SplitItem(proportion=2, content=twist),
                            fl.SplitItem(proportion=2, content=teleop),
                            fl.SplitItem(proportion=1, content=colors),
                            fl.SplitItem(proportion=1, content=run),
                        ],
                    ),
                ),
            ],
        )
    )


def layout_json():
    """The shipped file's text: the layout as indented JSON."""
    return json.dumps(json.loads(build_layout().to_json()), indent=2) + "\n"


if __name__ == "__main__":
    from pathlib import Path

    from ..cli.errors import run_cli
    from ..cli.parser import CommandParser
    from ..sim.files import write_atomic

    PROG = "python -m fpga_robotics.ros.layout"

    def _main(argv):
        target = Path(__file__).with_name("foxglove_layout.json")
        # No options; --help or a stray argument must not rewrite the shipped file.
        parser = CommandParser(prog=PROG, description=f"Write {target} again from its builder.")
        parser.parse_args(argv)
        write_atomic(target, layout_json(), what="layout")
        print(f"wrote {target}", file=sys.stderr)

    run_cli(_main, prog=PROG)
