"""Real-clock timing: every design cycle simulated, each at its instant of world time.

Edge ``e`` of the design clock happens at ``e / sim.clock_hz`` seconds (50 MHz by default, as
on the board). The world advances in physics steps of ``sim.physics_dt``; within each step the
design runs the step's edges, stopping wherever a watched output changes (an ultrasound TRIG,
the frame strobe) so that the connector concerned acts at that very edge
(``fpga_robotics.loop.connectors.base``), and where the wheel and servo pins are sampled (the
last edge whose change acts at a step: fpga_robotics.loop.connectors.sampling). Per step:

1. every sensor connector's ``before_step`` drives its inputs for the step (values now or at
   exact future edges);
2. the design runs to the step's last edge, stop by stop;
3. every connector's ``after_step``; due wheel commands go to the motors; the world steps.

The camera captures frame ``k`` at ``k / fps`` as in compressed timing; its pixels then reach
the design spread over the frame period like an OV7670's (line and frame blanking,
``sim.pins.timing.real_clock_timing``), so a frame's results come out about a frame period
after the capture and the command acts ``sim.actuation_delay`` after the wheel pins change.
Trajectory row ``k`` holds the world at the capture of frame ``k``, the per-frame outputs of
that frame (at its ``frame_done``) and the wheel pins at the next capture. A design without a
camera (``follow_line``) has its rows sampled at the camera's frame rate all the same.
"""

import hashlib
import re
from collections import deque

import numpy as np

from fpga_robotics.checks.sensor_metrics import line_metrics, measurement_metrics
from fpga_robotics.designs.builtin import TOPS, build_component, connector_kinds
from fpga_robotics.designs.reference import resolve_design, stream_ports
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.loop.bindings import (
    no_port,
    port_misfit,
    scenario_top,
    unbound,
)
from fpga_robotics.loop.compressed import ClosedLoop, run_loop
from fpga_robotics.loop.connectors import CONNECTORS, PinIO
from fpga_robotics.loop.pin_shadow import MirroredPins, PinComparison, ShadowStopped
from fpga_robotics.sim.backends.base import FrameResult
from fpga_robotics.sim.backends.foreign import ForeignDesign
from fpga_robotics.sim.backends.port_map import load_port_map
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.pins import (
    DesignError,
    DesignStopped,
    PinDesignSource,
    ShadowDesignError,
    VerilogPinSource,
    get_pin_backend,
    kept_source,
)
from fpga_robotics.sim.pins.timing import real_clock_timing
from fpga_robotics.sim.records import SensorReading

__all__ = [
    "RealClockLoop",
    "check_pin_backend",
    "format_extra_outputs",
    "make_pin_backend",
    "pin_design_source",
    "run_real_clock",
]

#: Per-frame outputs read when the frame strobe rises (the wheels are read at the next capture).
_FRAME_OUTPUTS = ("found", "proximity", "centroid_x", "centroid_leds")
_FRAME_STROBE = "frame_done"
#: Each connector's random stream: ``default_rng([seed, _CONNECTOR_STREAM, index])``.
_CONNECTOR_STREAM = 0xC011


def pin_design_source(scenario):
    """The pin design of the scenario: a ``PinDesignSource`` of ``design.top`` and its
    tables, or a ``VerilogPinSource`` of its foreign Verilog design."""
    if scenario.foreign is not None:
        design = ForeignDesign(
            scenario.foreign.verilog,
            scenario.foreign.ports,
            scenario.params,
            pins=True,
            connector_kinds=connector_kinds(),
            overrides=scenario.foreign.overrides,
        )
        # Without outputs.motor_left and motor_right the robot stands: the wheels are absent.
        return VerilogPinSource(design)
    top = scenario_top(scenario)
    params, tables = scenario.params, scenario.design_tables
    described = (
        f"{scenario.top}:{params!r}:{sorted(tables.items())!r}:"
        f"{sorted(scenario.design_params.items())!r}"
    )
    name = re.sub(r"[^A-Za-z0-9_]", "_", top.name)[:40]
    key = f"{name}-{hashlib.sha256(described.encode()).hexdigest()[:16]}"
    extra = {}
    if top.camera:
        extra = {"pixels": stream_ports(top.bindings), "frame_size": (params.width, params.height)}

        ports = resolve_design(scenario.top, scenario.design_params).ports
        if ports.get("filtered__valid", ("",))[0] == "out" and "filtered__payload" in ports:
            extra["filtered"] = ("filtered__valid", "filtered__payload")
    return kept_source(
        key,
        top,
        lambda: PinDesignSource(lambda: build_component(top, params, tables), key, **extra),
    )


def _result_strobe(scenario):
    """``(port, latency, timeout)`` of the result strobe of the scenario's Verilog design;
    None for a design without one (``after_cycles``, no camera, an Amaranth design)."""
    if scenario.foreign is None:
        return None
    pm = load_port_map(scenario.foreign.ports)
    if not pm.has_pixels or not pm.strobe:
        return None
    return pm.strobe, pm.latency, pm.timeout


def check_pin_backend(name):
    """``UsageError`` for a backend by name that cannot run a design on pins (the model
    backend), checked before anything is built."""
    if name == "model":
        raise UsageError(
            'the model backend runs whole frames; sim.timing = "real_clock" '
            "needs a backend that simulates every clock: --backend auto, "
            "cxxrtl, verilator or pysim"
        )


def make_pin_backend(name, scenario, *, on_build=None):
    """A pin-level backend by name ("auto": the fastest compiled one) for the scenario."""
    check_pin_backend(name)
    kwargs = {"on_build": on_build} if on_build is not None else {}
    backend = get_pin_backend(name, pin_design_source(scenario), **kwargs)
    top = scenario_top(scenario)
    # Which port serves which connector pin: a loop that runs it as a shadow mirrors the
    # primary's inputs by it (pin_shadow.MirroredPins), records its wheels and extra
    # outputs, and reports the parameters of a design of one's own (None: it takes none).
    backend.connector_bindings = top.bindings
    backend.extra_outputs = dict(top.extra_outputs)
    own = scenario.foreign is None and scenario.top not in TOPS
    backend.design_params = dict(scenario.design_params) if own else None
    return backend


def format_extra_outputs(summary):
    """The summary's ``extra_outputs`` as lines for the terminal (none without any)."""
    extra = summary.get("extra_outputs") or {}
    return [
        f"  design output {name}: last {v['last']}, min {v['min']}, max {v['max']}"
        for name, v in extra.items()
    ]


class _PendingRow:
    """Trajectory row ``k`` between its capture and the end of its frame's processing."""

    __slots__ = (
        "cameras",
        "distance",
        "edge",
        "events",
        "filtered",
        "k",
        "outputs",
        "readings",
        "rgb",
        "t",
        "viewer_events",
        "visible",
    )

    def __init__(self, k, t, rgb, events, distance, visible, edge, readings):
        self.k, self.t, self.rgb, self.events = k, t, rgb, events
        self.distance, self.visible, self.edge = distance, visible, edge
        self.readings = readings  # {connector name: SensorReading} at the capture
        self.outputs = None  # the per-frame outputs, at the frame strobe
        self.filtered = None
        self.viewer_events = []  # events already in the run's list at their exact time
        self.cameras = {}  # further cameras' latest captures (loop/camera_rig.py)


class RealClockLoop(ClosedLoop):
    """``ClosedLoop`` in real-clock timing, on a ``PinBackend`` (``design``)."""

    #: What a world checkpoint (fpga_robotics.loop.checkpoint) keeps beyond a compressed
    #: loop's state: the pin connectors and what the loop knows of the pins.
    EXTRA_STATE = (
        "sensors",
        "io",
        "watched",
        "last",
        "pending",
        "frame_outputs",
        "extra",
        "measurements",
        "awaited",
    )

    def __init__(
        self,
        scenario,
        *,
        design,
        seed=None,
        recorder=None,
        on_frame=None,
        controls=None,
        shadow=None,
        shadow_label="shadow",
    ):
        self.primary = design  # the primary's own backend (a journal, when forking)
        if shadow is not None:  # a second design, given every input the primary gets
            design = MirroredPins(design, shadow)
        super().__init__(
            scenario,
            seed=seed,
            design=design,
            recorder=recorder,
            on_frame=on_frame,
            controls=controls,
        )
        self.top = scenario_top(scenario)
        self.clock_hz = scenario.sim.clock_hz
        self.pins = design
        self.motors.configure_real_clock(self.dt, scenario.sim.actuation_delay)
        # Further cameras and servos are the rig's (loop/camera_rig.py); the rest are here.
        connectors = [c for c in scenario.connectors if c.kind not in ("camera", "servo")]
        self.sensors = [
            CONNECTORS[spec.kind](
                spec.name,
                spec.mount,
                spec.params,
                world=self.world,
                rng=np.random.default_rng([self.seed, _CONNECTOR_STREAM, i]),
            )
            for i, spec in enumerate(connectors)
        ]
        specs = {c.name: s for c, s in zip(self.sensors, connectors)}
        self.io = {}  # connector -> PinIO
        self.watched = {}  # design port -> (connector or None, pin)
        # A design without wheel outputs leaves the robot standing: the motors get no pins.
        self.wheels = "wheels" in self.top.bindings
        for conn in [self.motors, *self.sensors] if self.wheels else self.sensors:
            binding = dict(self.top.bindings.get(conn.kind, {}))
            if conn in self.sensors:
                binding.update(specs[conn.name].ports)
            self.io[conn] = PinIO(design, self._checked(conn, binding), self.clock_hz)
            for pin in conn.watch:
                self.watched[self.io[conn].binding[pin]] = (conn, pin)
        if self.rig is not None:  # the rig streams its cameras; its servos hear their pins
            self.rig.use_pins(design, self.clock_hz)
            for servo in self.rig.servos.values():
                servo.port = servo.port or self.top.bindings.get("servo", {}).get("angle")
                if servo.port is not None:  # sampled, as the wheels (run_design_to)
                    binding = self._checked(servo, {"angle": servo.port})
                    self.io[servo] = PinIO(design, binding, self.clock_hz)
        self._check_inputs_driven()
        if shadow is not None:
            self._mirror_connectors(getattr(shadow, "connector_bindings", {}), specs)
        if self.top.camera and _FRAME_STROBE in design.ports:  # FollowTarget's frame outputs
            self.watched[_FRAME_STROBE] = (None, _FRAME_STROBE)
        if "obstacle" in self.top.extra_outputs.values():  # the interlock's events
            self.watched.setdefault("obstacle", (None, "obstacle"))
        self.last = {}  # watched port -> last value seen
        # A Verilog design's result strobe: (port, latency, timeout) of its map.
        self.strobe = _result_strobe(scenario) if self.top.camera else None
        # An Amaranth design's frame_done must rise within a frame period of the design clock
        # after the frame's last pixel, as in compressed timing (loop/pin_frames.py): else its
        # per-frame outputs are never read and the checks made of them not measured.
        self.frame_watchdog = None
        if self.top.camera and scenario.foreign is None and _FRAME_STROBE in design.ports:
            self.frame_watchdog = round(self.clock_hz / scenario.camera.fps)
        # The frames awaiting their results, oldest first: [(frame, last edge they may
        # come out at)].
        self.awaited = deque()
        self.pending = None  # the frame whose outputs are awaited: [k, t, rgb, events, result]
        self.frame_outputs = {}
        self.extra = {name: np.full(self.n_frames, np.nan) for name in self.top.extra_outputs}
        self.shadow_pins = shadow
        if shadow is not None:
            self.compared = self._compared_outputs(shadow)
            params = getattr(shadow, "design_params", None)
            self.comparison = PinComparison(shadow_label, tuple(self.compared), params=params)
        self.measurements = {}  # "<connector>.<key>" -> array per row

    def _compared_outputs(self, shadow):
        """Output -> (primary's port, shadow's port), compared at every row: the wheels
        through the ports each design binds them to (a new version may rename them), every
        other output both designs have by its name."""
        wheels = self.top.bindings.get("wheels", {})
        shadow_wheels = getattr(shadow, "connector_bindings", {}).get("wheels", {})
        wheel_of = {port: pin for pin, port in wheels.items()}
        compared = {}
        for name, port in self.pins.ports.items():
            if port.direction != "out" or name.startswith("filtered__"):
                continue
            pin = wheel_of.get(name)
            if pin is not None:
                if pin in shadow_wheels:
                    compared[pin] = (name, shadow_wheels[pin])
                continue
            other = shadow.ports.get(name)
            wheel = name in shadow_wheels.values()  # the shadow's, compared as its wheel
            if other is not None and other.direction == "out" and not wheel:
                compared[name] = (name, name)
        return compared

    def use_design(self, pins):
        """Drive ``pins`` from now on (a design brought to the loop's state, e.g. by
        fpga_robotics.loop.pin_journal)."""
        self.design = self.pins = pins
        self.restored()

    def restored(self):
        super().restored()
        for io in self.io.values():  # the connectors talk to this loop's design
            io.backend = self.pins
        if self.rig is not None:  # so do further cameras and servos
            self.rig.pins = self.pins

    # Binding ----------------------------------------------------------------------------

    def _checked(self, conn, binding):
        ports = self.pins.ports
        for pin in conn.pins:
            port = binding.get(pin)
            if port is None:
                raise unbound(conn.kind, conn.name, self.top, pin)
            if port not in ports:
                raise no_port(conn.kind, conn.name, self.top, pin, port, ports)
            misfit = port_misfit(conn.kind, conn.name, self.top, pin, ports[port], conn.pins[pin])
            if misfit is not None:
                raise UsageError(misfit)
        return binding

    def _mirror_connectors(self, bindings, specs):
        """Give the shadow design's input bound to each connector pin what the primary's
        input bound to it gets (``bindings``: the shadow's, its sensors' ``ports`` tables as
        the primary's)."""
        for pin, port in self.top.bindings.get("camera", {}).items():
            other = bindings.get("camera", {}).get(pin)
            if other is not None:
                self.pins.mirror(port, other)
        for conn, io in self.io.items():
            binding = dict(bindings.get(conn.kind, {}))
            if conn.name in specs:
                binding.update(specs[conn.name].ports)
            for pin, spec in conn.pins.items():
                if spec.direction == "in" and binding.get(pin) is not None:
                    self.pins.mirror(io.binding[pin], binding[pin])

    def _check_inputs_driven(self):
        """Every design input is driven: by the camera's stream, a connector's pin or the
        backend (a Verilog design's ``[runtime]`` inputs)."""
        driven = {port for io in self.io.values() for pin, port in io.binding.items()}
        pins = getattr(self.pins, "primary", self.pins)  # a shadow's MirroredPins: its primary
        driven |= set(getattr(getattr(pins, "source", None), "runtime", None) or ())
        if self.top.camera:
            driven |= {*stream_ports(self.top.bindings), *self.top.bindings["camera"].values()}
        if self.rig is not None:
            driven |= self.rig.driven_ports()
        for name, port in sorted(self.pins.ports.items()):
            if port.direction == "in" and name not in driven:
                kinds = [k for k, b in self.top.bindings.items() if name in b.values()]
                stream = re.fullmatch(r"(.+)__(valid|payload)", name)
                ready = re.fullmatch(r"(.+)__ready", name)
                valid = ready and self.pins.ports.get(f"{ready.group(1)}__valid")
                if kinds:
                    hint = f'declare a [[robot.sensors]] table with kind = "{kinds[0]}"'
                elif stream and not self.top.camera:
                    # A pixel stream under another name (pixel: In(...)): the camera's.
                    hint = (
                        f"to stream the camera to it, name it pixels or declare connectors = "
                        f'{{"camera": {{"pixels": "{stream.group(1)}"}}}}'
                    )
                elif valid and valid.direction == "out":
                    # No connector takes a stream from the design: nothing can say ready.
                    hint = (
                        f"it is the ready of its output stream {ready.group(1)!r}, which nothing "
                        "here takes (its valid and payload are recorded); declare it "
                        "stream.Signature(..., always_ready=True)"
                    )
                else:
                    hint = "bind a connector pin to it with ports = {...}"
                raise UsageError(
                    f"design {self.top.name!r}: nothing drives its input {name!r}; {hint}"
                )

    # The design clock --------------------------------------------------------------------

    def edge_of_step(self, step):
        return round(step * self.dt * self.clock_hz)

    def start_design(self):
        self.pins.watch(list(self.watched))
        self.last = {port: self.pins.peek(port) for port in self.watched}
        # The actuator pins' values out of reset are a command too (a design may start moving).
        for conn in self.sampled_actuators():
            conn.sample(self.io[conn])
        for conn in self.sensors:
            conn.start(self.io[conn])

    def sampled_actuators(self):
        """The connectors whose pins are sampled once a step rather than watched
        (fpga_robotics.loop.connectors.sampling): the wheels, the servos the design drives."""
        servos = self.rig.servos.values() if self.rig is not None else ()
        return [
            *((self.motors,) if self.wheels else ()),
            *(s for s in servos if s.port is not None),
        ]

    def run_design_to(self, edge):
        """Run the design up to ``edge``, handling every watched change where it happens
        and sampling the actuators' pins where their commands are decided."""
        sampled = [(conn, self.io[conn]) for conn in self.sampled_actuators()]
        while self.pins.cycle < edge:
            # They share dt and delay, so their sample edges agree; a sample more is harmless.
            due = min((c.sample_edge_after(io, self.pins.cycle) for c, io in sampled), default=edge)
            deadline = self.awaited[0][1] if self.awaited else edge
            try:
                stop = self.pins.run(min(edge, due, deadline) - self.pins.cycle)
            except DesignStopped as exc:
                shadow = isinstance(exc, ShadowStopped)
                raise (ShadowDesignError if shadow else DesignError)(
                    f"{self._shadow_name if shadow else self._design_name}: frame "
                    f"{max(0, self.frames_done - 1)}: the {'shadow ' * shadow}design called "
                    f"{exc.call} (edge {exc.cycle}, {exc.cycle / self.clock_hz:.6g} s)"
                ) from None
            if self.pins.cycle == due:
                for conn, io in sampled:
                    conn.sample(io)
            if stop.port is not None:
                self._handle_changes(stop.cycle / self.clock_hz)
            self._check_strobe_timeout()

    def _handle_changes(self, t):
        """Every watched output that changed at the edge just run (world time ``t``)."""
        for port, (conn, pin) in self.watched.items():  # several may change on one edge
            value = self.pins.peek(port)
            if value == self.last[port]:
                continue
            self.last[port] = value
            if conn is not None:
                conn.on_change(self.io[conn], pin, value, t)
            else:
                self.design_output_changed(port, value, t)

    @property
    def _design_name(self):
        """The design as its errors name it: a Verilog design by its top module."""
        return self.top.name.removeprefix("verilog:")

    @property
    def _shadow_name(self):
        """The shadow design as its errors name it: as ``--shadow`` gave it."""
        return self.comparison.label.removeprefix("verilog:")

    def _check_strobe_timeout(self):
        """The oldest frame awaiting its result strobe has not had it by its last edge: the
        timeout of compressed timing (``result.timeout`` cycles after the frame's last
        pixel), named the same way."""
        if not self.awaited or self.pins.cycle < self.awaited[0][1]:
            return
        frame = self.awaited[0][0]
        if self.strobe is None:
            p = self.scenario.params  # the size, for a design that counts its own
            raise DesignError(
                f"{self._design_name}: frame {frame}: frame_done did not rise within "
                f"{self.frame_watchdog:,} edges (a frame period at sim.clock_hz) after the "
                f"frame's last pixel (a {p.width}x{p.height} frame, camera.resolution); the "
                "per-frame outputs are read when it rises: raise it once a frame"
            )
        port, _latency, timeout = self.strobe
        raise DesignError(
            f"{self._design_name}: frame {frame}: timeout: the result strobe "
            f"{port!r} never rose within {timeout} cycles (result.timeout) after the frame"
        )

    def design_output_changed(self, port, value, t):
        if port == _FRAME_STROBE:
            if value and self.awaited:  # the oldest frame's results are out
                self.awaited.popleft()
            if value and self.pending is not None and self.pending.outputs is None:
                # A foreign design's absent outputs are no ports: None in the row.
                self.pending.outputs = {
                    name: self.pins.peek(name) for name in _FRAME_OUTPUTS if name in self.pins.ports
                }
                self.pending.filtered = self.pins.filtered_frame()
        elif port == "obstacle":
            text = (
                "interlock: obstacle, wheels stopped"
                if value
                else "interlock: clear, wheels released"
            )
            row = self.pending
            self.events.append((row.k if row is not None else 0, round(t, 6), text))
            if row is not None:  # shown in the viewer with the row it happened in
                row.viewer_events.append(text)

    def advance_physics(self, to_step):
        rig = self.rig
        while self.step < to_step:
            t = self.step * self.dt
            for conn in self.sensors:
                conn.before_step(self.io[conn], t, self.dt)
            if rig is not None:  # due servo commands, captures streamed from the next edge
                rig.before_step(self.step, self.world)
            self.run_design_to(self.edge_of_step(self.step + 1))
            for conn in self.sensors:
                conn.after_step(self.io[conn], t + self.dt)
            self.motors.apply_due(self.step)
            self.world.step(self.dt)
            if rig is not None:
                rig.after_step(self.dt)
            self.step += 1
        self.motors.apply_due(self.step)

    # Frames --------------------------------------------------------------------------------

    def run_frame(self, k):
        if k == 0:
            self.start_design()
        self.advance_physics(round(k * self.period / self.dt))
        t = self.step * self.dt
        self.finish_row()
        rgb, events = None, []
        if self.top.camera or self.want_records:
            pose, rgb, events = self.capture(t)
        else:
            pose = self.camera.pose(self.world.robot_pose(), self.world.camera_pitch)
            events = list(self.world.drain_events())
        events += self.apply_controls(k, t)
        if self.top.camera:
            self._stream(k, rgb)
        distance, visible = self.measure_world(k, t, pose)
        readings = self.read_sensors(k)
        cameras = {}
        if self.rig is not None:
            self.rig.sample(k, self.n_frames, self.world)
            if self.want_records:
                readings.update(self.rig.readings(self.world))
                cameras = self.rig.views()
        self.pending = _PendingRow(k, t, rgb, events, distance, visible, self.pins.cycle, readings)
        self.pending.cameras = cameras
        self.frames_done = k + 1

    def read_sensors(self, k):
        """The connectors' measurements into row ``k``; their readings for the viewer."""
        readings = {}
        for conn in self.sensors:
            values = conn.measurement()
            for key, value in values.items():
                column = self.measurements.setdefault(
                    f"{conn.name}.{key}", np.full(self.n_frames, np.nan)
                )
                column[k] = np.nan if value is None else float(value)
            if self.want_records:
                overlay = conn.map_overlay()
                readings[conn.name] = SensorReading(
                    conn.kind,
                    dict(values),
                    tuple(overlay.get("points", ())),
                    tuple(overlay.get("states", ())),
                    tuple(overlay.get("rays", ())),
                    float(overlay.get("height", 0.0)),
                    overlay.get("scan"),
                )
        return readings

    def _stream(self, k, rgb):
        p = self.scenario.params
        color_port = self.top.bindings["camera"].get("color_sel")
        if color_port is not None:  # a camera design may have no colour select
            self.pins.poke(color_port, self.color_code)
        timing = real_clock_timing(
            p.width, p.height, self.scenario.camera.fps, self.clock_hz, self.pins.cycle + 1
        )
        if self.pins.frame_pending:
            raise UsageError(
                "a camera frame is still streaming when the next is captured; "
                "lower camera.fps or raise sim.clock_hz"
            )
        self.pins.stream_frame(to_rgb444(rgb, p.width, p.height), timing)
        last_pixel = timing.last_edge(p.width, p.height)
        if self.strobe is not None:
            # frame_done follows the strobe by the map's latency (the pin wrapper).
            _port, latency, timeout = self.strobe
            self.awaited.append((k, last_pixel + timeout + latency))
        elif self.frame_watchdog is not None:
            self.awaited.append((k, last_pixel + self.frame_watchdog))

    def finish_row(self):
        """Complete the pending row: its outputs, the wheel pins now, events, the record."""
        row, self.pending = self.pending, None
        if row is None:
            return
        outputs = row.outputs or {}
        values = {name: (outputs.get(name) if self.top.camera else None) for name in _FRAME_OUTPUTS}
        wheels = self.io[self.motors].binding if self.wheels else {}
        for pin in ("motor_left", "motor_right"):  # absent without wheels
            values[pin] = self.pins.peek(wheels[pin]) if pin in wheels else None
        result = FrameResult(filtered=row.filtered, cycles=self.pins.cycle - row.edge, **values)
        self.store_outputs(row.k, result)
        events = row.events
        if result.found is not None:
            events += self.design_events.update(bool(result.found))
        extra = {}
        for name, port in self.top.extra_outputs.items():
            extra[name] = self.pins.peek(port)
            self.extra[name][row.k] = float(extra[name])
            self.exact_extra.setdefault(name, {})[row.k] = extra[name]
        shadow = {}
        if self.shadow_pins is not None:
            events += self.compare_shadow(row)
            if self.want_records:
                shadow = self.shadow_outputs()
        self.events += [(row.k, round(row.t, 6), e) for e in events]
        if self.want_records:
            self.record(
                row.k,
                row.t,
                row.rgb,
                result,
                row.distance,
                row.visible,
                events + row.viewer_events,
                sensors=row.readings,
                design_extra=extra,
                cameras=row.cameras,
                camera_input=bool(self.top.camera),
                **shadow,
            )

    def shadow_outputs(self):
        """The shadow design's outputs now, as the row's record holds them: its per-frame
        outputs and wheels (through its own ports) as ``shadow_result``, the outputs no
        connector reads as ``shadow_extra``."""
        pins = self.shadow_pins
        bindings = pins.connector_bindings
        camera = "camera" in bindings
        values = {
            name: pins.peek(name) if camera and name in pins.ports else None
            for name in _FRAME_OUTPUTS
        }
        wheels = bindings.get("wheels", {})
        for pin in ("motor_left", "motor_right"):
            values[pin] = pins.peek(wheels[pin]) if pin in wheels else None
        return {
            "shadow_result": FrameResult(filtered=None, cycles=None, **values),
            "shadow_extra": {name: pins.peek(port) for name, port in pins.extra_outputs.items()},
        }

    def compare_shadow(self, row):
        """Row ``row.k``'s outputs of both designs compared; the event of the first
        divergence."""
        c = self.comparison
        first = c.first_divergence is None
        # Read past a journal (fpga_robotics.loop.pin_journal): the loop's own calls only.
        design = getattr(self.pins.primary, "unrecorded", self.pins.primary)
        primary = {n: design.peek(port) for n, (port, _) in self.compared.items()}
        shadow = {n: self.shadow_pins.peek(port) for n, (_, port) in self.compared.items()}
        differ = c.compare(row.k, row.t, primary, shadow)
        if not (differ and first):
            return []
        parts = ", ".join(f"{n} {primary[n]} vs {shadow[n]}" for n in differ)
        return [f"shadow design {c.label} diverges: {parts}"]

    def after_frames(self):
        self.finish_row()
        # Extra columns: "design.<output>" and "<connector>.<measurement>".
        self.traj.update({f"design.{k}": v for k, v in self.extra.items()})
        self.traj.update(self.measurements)

    def extra_metrics(self):
        """Also the line metrics, over the world's floor lines, from the line sensors' mounts,
        and how often each sensor measured."""
        mounts = [m for c in self.sensors if c.kind == "line_sensors" for m in c.sensor_mounts]
        return {
            **super().extra_metrics(),
            **line_metrics(self.traj, getattr(self.world, "floor_lines", ()), mounts, self.period),
            **measurement_metrics(
                self.measurements, [(c.name, c.kind) for c in self.sensors], self.frames_done
            ),
        }

    def timing_summary(self, wall):
        cycles = self.pins.cycle
        return {
            "timing": "real_clock",
            "clock_hz": self.clock_hz,
            "sim_cycles": cycles,
            "cycles_per_wall_s": round(cycles / wall) if wall > 0 else None,
        }


def run_real_clock(
    scenario,
    *,
    seed,
    backend,
    recorder,
    progress,
    realtime,
    on_frame,
    shadow,
    shadow_label,
    controls,
):
    """``run_scenario`` (fpga_robotics.loop.timings) in real-clock timing."""
    if shadow is not None and not hasattr(shadow, "ports"):
        raise UsageError(
            "a shadow in real-clock timing is a design on a pin backend "
            "(run --shadow REF); FollowTarget parameters compare frames in "
            'sim.timing = "compressed"'
        )
    return run_loop(
        backend,
        lambda name: make_pin_backend(name, scenario),
        lambda design: RealClockLoop(
            scenario,
            seed=seed,
            design=design,
            recorder=recorder,
            on_frame=on_frame,
            controls=controls,
            shadow=shadow,
            shadow_label=shadow_label,
        ),
        shadow=shadow,
        progress=progress,
        realtime=realtime,
    )
