"""Further cameras and pan servos in compressed timing: ``[[robot.sensors]]`` of kind
``camera`` and ``[[robot.actuators]]`` of kind ``servo``.

Each camera has its own mount (on the body, or on a servo with ``on = "<servo>"``: the
servo's horn turns it), resolution, frame rate and port bundle (``ports = {pixels = ...,
color_sel = ...}``). Its frame ``j`` is captured at ``j / fps`` (rounded to a physics step,
as the body camera's), rendered from the same world state as everything else at that
instant, and goes through the design's channel on that bundle (``Top.frame_channels``: the
channel's frame-level model). An output of the channel a servo is bound to (``angle``, e.g.
``servo_angle``) is a servo command that acts ``sim.actuation_delay`` after the capture, as
the wheel commands; the horn then slews at the servo's speed (sim/world/servo.py), one
physics step at a time. Trajectory rows (one per body-camera frame) sample every camera's
latest outputs and every servo's angle at the row's instant.

In real-clock timing (``use_pins``) the design itself is the channel: each capture's pixels
reach its port bundle spread over the frame period as the body camera's do
(``sim.pins.timing.real_clock_timing``, scheduled edge by edge), and the servo hears its pin
change at the very edge (the loop watches it), its command acting ``sim.actuation_delay``
later.
"""

import importlib
import math

import numpy as np

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.pixel import color_select_value
from fpga_robotics.loop.connectors import CONNECTORS, CameraConnector, in_view
from fpga_robotics.loop.connectors.camera import make_sensor
from fpga_robotics.loop.pin_channel import PinFrameChannel
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.camera.scene import CameraPose
from fpga_robotics.sim.pins.timing import real_clock_timing
from fpga_robotics.sim.records import CameraView, SensorReading

__all__ = ["CameraRig", "RigCamera", "frame_channel"]

#: A further camera's noise stream: ``default_rng([seed, _CAMERA_STREAM, index])``.
_CAMERA_STREAM = 0xCA3F
_SERVO_STREAM = 0x5E7F


class RigCamera:
    """One further camera: its connector (renderer), its mount, its design channel."""

    def __init__(self, spec, connector, servo, channel, port, color_port):
        self.spec, self.params = spec, spec.params
        self.name, self.mount = spec.name, spec.mount
        self.connector, self.servo = connector, servo
        self.channel, self.port, self.color_port = channel, port, color_port
        self.channel_ran = "model"  # or the clocked backend running it (run_channels_on)
        self.color_code = color_select_value(self.params.color)
        self.frames = 0
        self.next_step = 0
        self.outputs = {}
        self.view = None  # the latest CameraView
        self.streaming_until = None  # real-clock timing: the edge after its frame's last pixel

    def turn_rate(self, world):
        """How fast the camera turns now, rad/s: the body's turn and the horn's it is on."""
        horn = self.servo.model.rate if self.servo is not None else 0.0
        return world.robot_velocity()[1] + horn

    def pose(self, world):
        """The camera's pose now: the body's pose, the servo's mount and angle if it is on
        one, then its own mount (relative to the horn, or to the body); on a slope it pitches
        along the way it faces."""
        x, y, heading = world.robot_pose()
        if self.servo is not None:
            x, y, heading = self.servo.mount.world_pose(x, y, heading)
            heading += self.servo.angle
        m = self.mount
        c, s = math.cos(heading), math.sin(heading)
        return CameraPose(
            x=x + m.forward * c - m.left * s,
            y=y + m.forward * s + m.left * c,
            heading=heading + m.yaw,
            height=m.height,
            tilt=self.params.tilt + world.camera_pitch(heading + m.yaw),
        )


class CameraRig:
    """The further cameras and the servos of one run (``build`` returns None without any)."""

    def __init__(self, cameras, servos, dt, delay, people):
        self.cameras, self.servos = cameras, servos
        self.dt, self.delay_steps = dt, delay
        self.people = people  # names of the scenario's people
        self.columns = {}
        self.pins = None  # real-clock timing: the design on its pin backend (use_pins)
        self.end_step = math.inf  # the run's last physics step (no capture at or after it)

    def use_pins(self, pins, clock_hz):
        """Real-clock timing: stream the captures into ``pins`` (a ``PinBackend``) on a
        ``clock_hz`` clock instead of the channels' models."""
        self.pins, self.clock_hz = pins, clock_hz

    def run_channels_on(self, backend, scenario, top, *, on_build=None):
        """Compressed timing on a clocked backend (``pysim``, ``cxxrtl``, ``verilator``): each
        camera's channel runs on the design itself on that pin backend instead of its model."""
        for cam in self.cameras:
            if cam.channel is not None:
                cam.channel = PinFrameChannel(
                    cam.channel, scenario, top, cam.port, backend, on_build=on_build
                )
                cam.channel_ran = backend

    def close(self):
        for cam in self.cameras:
            close = getattr(cam.channel, "close", None)
            if close is not None:
                close()

    def driven_ports(self):
        """The design inputs the cameras drive (their port bundles)."""
        ports = set()
        for cam in self.cameras:
            if cam.port:
                ports |= {f"{cam.port}__valid", f"{cam.port}__payload", cam.color_port}
        return ports

    @classmethod
    def build(cls, scenario, world, seed, top):
        specs = [s for s in scenario.connectors if s.kind in ("camera", "servo")]
        if not specs:
            return None
        servos = {}
        for i, spec in enumerate(s for s in specs if s.kind == "servo"):
            servo = CONNECTORS["servo"](
                spec.name,
                spec.mount,
                spec.params,
                world=world,
                rng=np.random.default_rng([seed, _SERVO_STREAM, i]),
            )
            servo.configure(scenario.sim.physics_dt, scenario.sim.actuation_delay)
            bound = top.bindings.get("servo", {}) if top is not None else {}
            servo.port = spec.ports.get("angle") or bound.get("angle")
            servos[spec.name] = servo
        people = [p.name for p in world.people_states()]
        cameras = [
            _camera(scenario, spec, i, seed, top, servos)
            for i, spec in enumerate(s for s in specs if s.kind == "camera")
        ]
        delay = round(scenario.sim.actuation_delay / scenario.sim.physics_dt)
        rig = cls(cameras, servos, scenario.sim.physics_dt, delay, people)
        rig.end_step = max(1, round(scenario.sim.duration / scenario.sim.physics_dt))
        return rig

    # The physics steps ---------------------------------------------------------------------

    def before_step(self, step, world):
        """At step ``step`` (the world at its instant): due servo commands, then the captures
        due (each through its channel; its commands scheduled)."""
        for servo in self.servos.values():
            servo.apply_due(step)
        for cam in self.cameras:
            if cam.next_step == step < self.end_step:  # as the body camera: inside the run
                self._capture(cam, step, world)

    def _capture(self, cam, step, world):
        pose = cam.pose(world)
        rgb = cam.connector.capture(world.scene(), pose, cam.turn_rate(world))
        if self.pins is not None:
            if cam.channel is not None:
                self._stream(cam, rgb)
        elif cam.channel is not None:
            cam.outputs = cam.channel.process(rgb, cam.color_code)
            for servo in self.servos.values():
                if servo.port in cam.outputs:
                    servo.schedule(step + self.delay_steps, cam.outputs[servo.port])
                    servo.apply_due(step)  # a zero delay acts now
        found_port, cx_port = getattr(cam.channel, "view_ports", (None, None))
        found, cx = cam.outputs.get(found_port), cam.outputs.get(cx_port)
        cam.view = CameraView(
            rgb,
            pose,
            cam.params.hfov,
            step * self.dt,
            None if found is None else bool(found),
            cx,
        )
        cam.frames += 1
        cam.next_step = round(cam.frames * cam.params.frame_period / self.dt)

    def _stream(self, cam, rgb):
        """The frame's pixels on the camera's port bundle, one scheduled beat each, from the
        next edge on, as an OV7670 spreads them over the frame period."""

        p, pins = cam.params, self.pins
        if cam.streaming_until is not None and cam.streaming_until > pins.cycle:
            raise UsageError(
                f"camera {cam.name!r}: a frame is still streaming when the next is captured; "
                "lower its fps or raise sim.clock_hz"
            )
        timing = real_clock_timing(p.width, p.height, p.fps, self.clock_hz, pins.cycle + 1)
        packed = to_rgb444(rgb, p.width, p.height).astype(np.int64)
        packed[0, 0] |= 1 << 12  # first
        packed[:, -1] |= 1 << 13  # last (of each line)
        valid, payload = f"{cam.port}__valid", f"{cam.port}__payload"
        pins.poke(cam.color_port, cam.color_code)
        gap = timing.pixel_period > 1
        for y in range(p.height):
            row = packed[y].tolist()
            for x in range(p.width):
                edge = timing.edge_of(y, x)
                pins.schedule(edge, payload, row[x])
                pins.schedule(edge, valid, 1)
                if gap or x == p.width - 1:
                    pins.schedule(edge + 1, valid, 0)
        cam.streaming_until = timing.last_edge(p.width, p.height) + 1

    def after_step(self, dt):
        for servo in self.servos.values():
            servo.step(dt)

    # Rows, the viewer, the metrics -----------------------------------------------------------

    def sample(self, k, n_rows, world):
        """Row ``k``: each servo's angle and command, each camera's channel outputs and its
        target's bearing off its axis (deg) and visibility now."""

        def put(name, value):
            self.put(name, k, n_rows, value)

        for name, servo in self.servos.items():
            for key, value in servo.measurement().items():
                put(f"{name}.{key}", value)
        people = {p.name: p for p in world.people_states()}
        heights = {p.name: p.height for p in world.config.people}
        for cam in self.cameras:
            if self.pins is not None and cam.channel is not None:  # the design's ports now
                ports = [*cam.channel.view_ports, *(s.port for s in self.servos.values())]
                cam.outputs = {port: self.pins.peek(port) for port in ports if port}
            for port, value in cam.outputs.items():
                put(f"{cam.name}.{port}", value)
            target = people.get(cam.params.target)
            if target is None:
                continue
            pose = cam.pose(world)
            visible = in_view(
                pose, cam.params, target.x, target.y, target.radius, heights[target.name]
            )
            put(f"{cam.name}.target_in_view", visible)
            put(f"{cam.name}.target_bearing_deg", angle_off_axis(pose, target.x, target.y))

    def put(self, name, k, n_rows, value):
        """Column ``name``'s row ``k`` (of ``n_rows``); None is NaN."""
        column = self.columns.setdefault(name, np.full(n_rows, np.nan))
        column[k] = np.nan if value is None else float(value)

    def views(self):
        return {cam.name: cam.view for cam in self.cameras if cam.view is not None}

    def readings(self, world):
        """Each servo as a sensor reading for the viewer: its angle, and a ray along the
        horn's direction on the map."""
        x, y, heading = world.robot_pose()
        readings = {}
        for name, servo in self.servos.items():
            sx, sy, sh = servo.mount.world_pose(x, y, heading)
            a = sh + servo.angle
            ray = ((sx, sy), (sx + 0.4 * math.cos(a), sy + 0.4 * math.sin(a)))
            readings[name] = SensorReading("servo", servo.measurement(), rays=(ray,))
        return readings

    def metrics(self, rows):
        """Per camera: its frames, what ran its channel and, with a target, how often that
        was in view and within ``centred_deg`` of the axis (None without one); the smallest
        of each over the cameras with a target (``camera_target_*_fraction``)."""
        per = {}
        for cam in self.cameras:
            per[cam.name] = {
                "frames": cam.frames,
                # What ran its design channel: the channel's model or the design on a clocked
                # backend (compressed timing), the design on the pin backend (real clock);
                # none for a camera that only films.
                "channel": None
                if cam.channel is None
                else "design"
                if self.pins is not None
                else cam.channel_ran,
                **self._target_metrics(cam, rows),
            }
        judged = [v for v in per.values() if v["target_in_view_fraction"] is not None]
        fractions = [v["target_in_view_fraction"] for v in judged]
        centred = [v["target_centred_fraction"] for v in judged]
        return {
            "cameras": per,
            "camera_target_in_view_fraction": min(fractions) if fractions else None,
            "camera_target_centred_fraction": min(centred) if centred else None,
        }

    def _target_metrics(self, cam, rows):
        """How often ``cam``'s target was in view and centred in the first ``rows`` rows, and
        the most it strayed (each None without a target or rows)."""
        if cam.params.target is None or not rows:
            return dict.fromkeys(
                ("target_in_view_fraction", "target_centred_fraction", "max_abs_bearing_deg")
            )
        seen = self.columns[f"{cam.name}.target_in_view"][:rows]
        bearing = self.columns[f"{cam.name}.target_bearing_deg"][:rows]
        centred = np.abs(bearing) <= cam.params.centred_deg
        return {
            "target_in_view_fraction": float(np.mean(seen == 1.0)),
            "target_centred_fraction": float(np.mean(centred)),
            "max_abs_bearing_deg": float(np.nanmax(np.abs(bearing))),
        }


def angle_off_axis(pose, x, y):
    """The bearing of ``(x, y)`` off the axis of a camera at ``pose``, degrees (left
    positive, -180..180)."""
    bearing = math.atan2(y - pose.y, x - pose.x) - pose.heading
    return math.degrees((bearing + math.pi) % (2 * math.pi) - math.pi)


def frame_channel(scenario, spec, top):
    """The design's channel a further camera's frames go through (its ``ports`` bundle), or
    None for a camera that films only; a ``UsageError`` naming what is wrong (no channel on
    that bundle, a size the channel does not take). Its ``on`` and ``target`` are checked
    at load (fpga_robotics.scenario)."""
    p, where = spec.params, f"camera {spec.name!r}"
    port = spec.ports.get("pixels")
    if port is None:
        return None
    channels = top.frame_channels if top is not None else {}
    where_to = channels.get(port)
    if where_to is None:
        name = top.name if top is not None else scenario.top
        raise UsageError(
            f"{where}: design {name!r} has no frame channel on pixels = {port!r}; "
            f"its channels: {', '.join(channels) or 'none'}"
        )
    module, name = where_to
    channel = getattr(importlib.import_module(module), name)(scenario.design_tables)
    if channel.frame_size != (p.width, p.height):
        w, h = channel.frame_size
        raise UsageError(
            f"{where}: its resolution {p.width}x{p.height} differs from the {w}x{h} "
            f"frames design {top.name!r} takes on {port!r}"
        )
    return channel


def _camera(scenario, spec, index, seed, top, servos):
    """A further camera from its ``[[robot.sensors]]`` spec."""
    p = spec.params
    servo = servos[p.on] if p.on is not None else None
    channel = frame_channel(scenario, spec, top)
    color_port = None if channel is None else spec.ports.get("color_sel", channel.color_port)
    port = spec.ports.get("pixels")
    connector = CameraConnector(
        p.width,
        p.height,
        p.hfov,
        mount_height=spec.mount.height,
        noise_std=p.noise_std,
        rng=np.random.default_rng([seed, _CAMERA_STREAM, index]),
        # camera.sensor = "ov7670": the body camera's sensor model, at this camera's size.
        sensor=make_sensor(scenario.camera, seed, (index, p)),
        renderer=scenario.camera.renderer,
        render3d=scenario.camera.render3d,
    )
    return RigCamera(spec, connector, servo, channel, port or "", color_port)
