"""The ROS and Foxglove options of ``python -m fpga_robotics.run``: ``--bag``, ``--live``,
``--interactive``, ``--replay-inputs``, ``--paused``.

``RosOutputs(args)`` checks them before the run starts; ``open(scenario)`` starts the bag
writer, the Foxglove server and the controls; ``on_frame`` is the per-frame callback;
``close(completed)`` finishes the bag (or removes it after a failure) and stops the rest.
"""

from fpga_robotics.hw.errors import UsageError

from .controls import LiveControls, ReplayControls, load_inputs, replay_mismatch
from .interactive import TerminalControls, check_terminal

__all__ = ["RosOutputs", "add_ros_arguments"]


def add_ros_arguments(p):
    p.add_argument(
        "--bag",
        metavar="PATH",
        help="also write the run as a ROS 2 bag (MCAP storage) in the folder PATH (docs/ros.md)",
    )
    p.add_argument(
        "--live",
        metavar="foxglove[:PORT]",
        help="publish the run's topics on a Foxglove WebSocket server on localhost "
        "(default port 8765), paced to real time, with live control from "
        "the client",
    )
    p.add_argument(
        "--interactive",
        action="store_true",
        help="control the run from the terminal: keys for colour, pause, step, "
        "driving the target person, speed (docs/ros.md)",
    )
    p.add_argument(
        "--paused", action="store_true", help="with --live or --interactive: start paused"
    )
    p.add_argument(
        "--replay-inputs",
        metavar="SUMMARY.json",
        help="replay the live inputs a run recorded (its --summary JSON) at the same frames",
    )


class RosOutputs:
    """The ROS/Foxglove side of one run; see the module docstring."""

    def __init__(self, args):
        self.bag_path = args.bag
        self.port = None
        self.interactive = args.interactive
        self.replay = None
        if args.bag is not None:
            from .bag_writer import check_bag_path  # lazy: rosbags (~0.15 s), only for --bag

            check_bag_path(args.bag)
        if args.live is not None:
            from .foxglove_live import (  # lazy: foxglove and rosbags, only for --live
                check_live_port,
                parse_live_spec,
            )

            self.port = parse_live_spec(args.live)
            check_live_port(self.port)
        if args.replay_inputs is not None:
            if self.port is not None or self.interactive:
                raise UsageError(
                    "--replay-inputs replays a run's inputs; it does not go with "
                    "--live or --interactive"
                )

            self.replay, self._steered = load_inputs(args.replay_inputs)
            self._replay_path = args.replay_inputs
        if self.interactive:
            check_terminal()
        self.live_control = self.port is not None or self.interactive
        if args.paused and not self.live_control:
            raise UsageError("--paused goes with --live or --interactive")
        self.start_paused = args.paused
        self.controls = None
        self._sinks = []  # bag writer, live publisher: each has log_frame and close
        self._bag = self._terminal = self._live = None

    def check_closed_loop_only(self, source):
        """With ``--source SPEC`` (no simulation) there is nothing to control, and only a
        camera's frames come at the pace of real time."""
        if self.interactive:
            raise UsageError("--interactive controls the closed loop (not with --source)")
        if self.replay is not None:
            raise UsageError("--replay-inputs replays a closed-loop run (not with --source)")
        if self.start_paused:
            raise UsageError("--paused pauses the closed loop (not with --source)")
        if self.port is not None and not str(source).startswith("camera:"):
            # A file is read as fast as the design goes: done before a client could connect.
            raise UsageError(
                "--live streams a run as it goes; with --source only a camera (camera:N) "
                "does: write the outputs of a video, folder or bag with --bag and open "
                "that in Foxglove"
            )

    def replay_warning(self, scenario, seed):
        """The warning when ``--replay-inputs`` replays a summary's inputs onto a run with
        another scenario, seed or overrides (``seed`` None: the scenario's), or None."""
        if self.replay is None:
            return None
        return replay_mismatch(
            self._replay_path,
            self._steered,
            scenario.name,
            scenario.seed if seed is None else seed,
            scenario.overrides,
        )

    @property
    def active(self):
        return (
            self.bag_path is not None
            or self.port is not None
            or self.replay is not None
            or self.interactive
        )

    def open(self, scenario, *, closed_loop=True):
        """Start what the options ask for; returns the notices to print now."""
        notices = []
        if not self.active:
            return notices
        from .bag_writer import BagWriter  # lazy: rosbags (~0.15 s), only for these options
        from .foxglove_live import LivePublisher  # lazy: foxglove, only for these options
        from .messages import camera_geometry  # lazy: rosbags' type store (~0.1 s)

        geometry = camera_geometry(scenario)
        try:
            if self.replay is not None:
                self.controls = ReplayControls(self.replay)
            elif self.live_control and closed_loop:
                self.controls = LiveControls(speed=1.0, paused=self.start_paused)
            if self.bag_path is not None:
                self._bag = BagWriter(self.bag_path, geometry)
                self._sinks.append(self._bag)
            if self.port is not None:
                self._live = LivePublisher(self.port, geometry, self.controls)
                self._sinks.append(self._live)
                notices += self._live.pop_notices()
            if self.interactive:
                self._terminal = TerminalControls(self.controls)
                notices += self._terminal.help_lines()
        except BaseException:
            self.close(False)
            raise
        return notices

    def on_frame(self, record):
        for sink in self._sinks:
            sink.log_frame(record)

    def summary_items(self):
        """``{"inputs": [...]}`` when the run had live or replayed inputs (with live ones
        ``"paused_s"``, the wall time it was held paused), and with a live server that took
        client messages, ``"refused_inputs"``: those it could not use."""
        items = {} if self.controls is None else {"inputs": list(self.controls.log)}
        if isinstance(self.controls, LiveControls):
            items["paused_s"] = round(self.controls.paused_s, 3)
        if self._live is not None and self._live.controls is not None:
            items["refused_inputs"] = self._live.refused_inputs()
        return items

    def close(self, completed):
        """Stop everything; the bag is kept only for a completed run. Returns notices."""
        notices = []
        if self._terminal is not None:
            self._terminal.close()
            self._terminal = None
        if self.controls is not None:
            self.controls.close()
            if completed and self.replay is None and self.controls.log:
                notices.append(
                    f"{len(self.controls.log)} live input(s) applied; the "
                    f"summary's 'inputs' replay them (--summary PATH, then "
                    f"--replay-inputs PATH)"
                )
            unreached = self.controls.unreached() if self.replay is not None else 0
            if completed and unreached:
                notices.append(
                    f"--replay-inputs: {unreached} input(s) after the run's last frame "
                    f"{self.controls.last_frame} were not applied"
                )
        for sink in self._sinks:
            if sink is self._bag and not completed:
                sink.abandon()
                continue
            text = sink.close()
            if text:
                notices.append(text)
        self._sinks = []
        return notices
