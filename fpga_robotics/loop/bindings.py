"""What a scenario's connectors bind to, checked from the design's declarations before a model
is built (``check_bindings``), and the test a pin's port passes (``port_misfit``), which the
real-clock loop applies again to the ports of the built design (a Verilog design's are known
only then).
"""

import dataclasses
import functools
import importlib
import math

from fpga_robotics.designs.builtin import TOPS, build_component, connector_kinds, foreign_top
from fpga_robotics.designs.reference import component_ports, resolve_design, signed_ports
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.loop.camera_rig import frame_channel
from fpga_robotics.loop.connectors import CONNECTORS
from fpga_robotics.sim.backends.port_map import check_connector_names, load_port_map
from fpga_robotics.sim.pins import PinError, Port
from fpga_robotics.sim.pins.timing import real_clock_timing

__all__ = ["check_bindings", "port_misfit", "scenario_top", "unbound"]


def scenario_top(scenario):
    """The ``Top`` (fpga_robotics.designs) the scenario runs: ``design.top`` resolved
    (designs/reference.py: its bindings and extra outputs), or for a foreign Verilog design
    (``design.verilog``) the one its port map describes."""
    if scenario.foreign is not None:
        port_map = load_port_map(scenario.foreign.ports)
        check_connector_names(port_map, connector_kinds())  # before its bindings are read
        return foreign_top(port_map)
    spec = resolve_design(scenario.top, scenario.design_params)
    spec.require_no_black_boxes()
    spec.require_defined_domains()
    if not spec.clocked:  # purely combinational: the simulators clock it through a wrapper
        return dataclasses.replace(
            spec.top, component=functools.partial(_clocked, spec.top.component)
        )
    return spec.top


def _clocked(factory):
    """The combinational design ``factory`` builds, with the clock a simulator drives."""
    from fpga_robotics.designs.clocked import ClockedCombinational  # lazy: Amaranth

    return ClockedCombinational(factory())


def check_bindings(scenario):
    """``UsageError`` for a connector binding the scenario's design cannot take, from the
    design's declarations and the port map, before a model is built: a sensor pin bound to
    no port, a design input two tables drive, a servo's port of the wrong kind, a camera's
    port bundle no channel of the design takes, in real-clock timing a sensor the design
    declares but the scenario leaves out."""
    top = scenario_top(scenario)
    _check_tables(scenario, top)
    if scenario.sim.timing == "real_clock":
        _check_declared_sensors(scenario, top)
        _check_pixel_rates(scenario, top)


def _check_tables(scenario, top):
    """The scenario's connector tables against the design's ports."""
    if not scenario.connectors:
        return
    registered = TOPS.get(scenario.top) if scenario.foreign is None else None
    for spec in scenario.connectors:
        if spec.kind == "camera":  # the rig's (loop/camera_rig.py), as it will build it
            frame_channel(scenario, spec, TOPS.get(scenario.top))
        if spec.kind in ("camera", "servo"):
            continue
        binding = {**top.bindings.get(spec.kind, {}), **spec.ports}
        for pin in CONNECTORS[spec.kind].pins:
            if binding.get(pin) is None:
                raise unbound(spec.kind, spec.name, top, pin)
    _check_single_drivers(scenario, top, registered)
    for spec in scenario.connectors:
        if spec.kind == "servo":
            _check_servo(scenario, spec, top, registered)


def _check_declared_sensors(scenario, top):
    """A sensor kind the design binds input pins of (its port map's ``[connectors.KIND]``,
    its Amaranth declarations) with no table of that kind in the scenario: nothing would
    drive those inputs (the real-clock loop refuses that once the model is built)."""
    present = {spec.kind for spec in scenario.connectors}
    for kind, binding in top.bindings.items():
        if kind == "camera" or kind in present or kind not in CONNECTORS:
            continue
        inputs = [binding[pin] for pin in _input_pins(kind) if binding.get(pin) is not None]
        if inputs:
            raise UsageError(
                f"design {top.name!r}: nothing drives its input {inputs[0]!r}; declare a "
                f'[[robot.sensors]] table with kind = "{kind}"'
            )


def _check_pixel_rates(scenario, top):
    """Each camera that streams into the design gets a line of pixels in a line period of the
    clock (``real_clock_timing``, as an OV7670), and each frame's pixels before its next
    capture, which falls on a physics step (as little as a whole number of steps below the
    frame period after the last): a camera that cannot is refused now, with the keys to
    change, rather than at its first frames."""
    sim = scenario.sim
    streams = []
    if top.camera:
        cam = scenario.camera
        streams.append(("camera", cam.width, cam.height, cam.fps, "camera"))
    for spec in scenario.connectors:
        if spec.kind == "camera" and spec.ports.get("pixels") is not None:
            p = spec.params
            streams.append((f"camera {spec.name!r}", p.width, p.height, p.fps, spec.where))
    for name, width, height, fps, where in streams:
        try:
            timing = real_clock_timing(width, height, fps, sim.clock_hz, 0)
        except PinError as exc:
            raise UsageError(
                f"{name}: {exc} ({where}.resolution, {where}.fps), or raise sim.clock_hz"
            ) from None
        steps = math.floor(1 / (fps * sim.physics_dt) + 1e-9)
        gap, last = steps * sim.physics_dt, timing.last_edge(width, height)
        # Two edges of slack: the captures' and the stream's own rounding to an edge.
        if last + 2 > math.floor(gap * sim.clock_hz) - 1:
            near = " or ".join(f"{1 / (n * sim.physics_dt):.4g}" for n in (steps + 1, steps))
            raise UsageError(
                f"{name}: {where}.fps {fps:g} on physics steps of {sim.physics_dt:g} s: its "
                f"captures fall on steps as little as {1000 * gap:.4g} ms apart, less than its "
                f"pixels take on the clock ({1000 * last / sim.clock_hz:.4g} ms); give it a "
                f"frame period of whole physics steps ({near} fps) or a shorter sim.physics_dt"
            )


def unbound(kind, name, top, pin):
    return UsageError(
        f"the {kind} connector {name!r}: design {top.name!r} has no port for its pin "
        f'{pin!r}; bind one with ports = {{{pin} = "PORT"}} in its [[robot.sensors]] table'
    )


def no_port(kind, name, top, pin, port, ports):
    return UsageError(
        f"the {kind} connector {name!r}: design {top.name!r} has no port {port!r} (for pin "
        f"{pin!r}); its ports: {', '.join(sorted(ports))}"
    )


def port_misfit(kind, name, top, pin, port, spec=None):
    """Why design ``port`` (a ``sim.pins.Port``) cannot be connector pin ``pin`` of the
    ``kind`` connector ``name``, or None when it can: of the pin's direction and width, or
    for a signed output pin (the wheels' DPS, a servo's angle) a signed output of at most its
    width, which the backends read sign-extended. ``spec``: the connector's own ``Pin`` where
    its width is set per connector (a line_sensors table's sensors), else the kind's."""
    spec = spec or CONNECTORS[kind].pins[pin]
    extended = spec.direction == "out" and spec.signed
    # An unsigned port of a signed pin's width would be read as a positive number: -100 as
    # 924 turns a servo to its end stop.
    fits = port.signed and port.width <= spec.width if extended else port.width == spec.width
    if port.direction == spec.direction and fits:
        return None
    if kind == "line_sensors":
        hint = (
            "; the line_sensors table must list as many sensors as the design's line input "
            "has bits (design.line.n_sensors)"
        )
    else:
        hint = (
            f"; it takes a signed output of at most {spec.width} bits (a narrower one is "
            "sign-extended)"
            if extended
            else ""
        )
    return (
        f"the {kind} connector {name!r}: pin {pin!r} is {spec.direction} {spec.width} bit(s)"
        f"{' signed' if extended else ''} but port {port.name!r} of design {top.name!r} is "
        f"{port.direction} {port.width} bit(s){' signed' if port.signed else ''}{hint}"
    )


def _check_single_drivers(scenario, top, registered):
    """Each design input is driven by one table: two LIDARs on one stream, or two cameras on
    one port bundle, would mix their data on the same pins."""
    drivers = {}  # design input -> the table that drives it
    for spec in scenario.connectors:
        for port in _inputs_driven(spec, top, registered):
            other = drivers.setdefault(port, spec)
            if other is not spec:
                if spec.kind == "camera":
                    how = (
                        'to another port bundle with ports = {pixels = "BUNDLE"}, or drop its '
                        "ports to film only"
                    )
                else:
                    pins = ", ".join(f'{pin} = "PORT"' for pin in _input_pins(spec.kind))
                    how = f"elsewhere with ports = {{{pins}}}, or leave it out"
                raise UsageError(
                    f"{spec.where} ({spec.name}) drives input {port!r}, which {other.where} "
                    f"({other.name}) drives too; bind it {how}"
                )


def _input_pins(kind):
    return [pin for pin, spec in CONNECTORS[kind].pins.items() if spec.direction == "in"]


def _inputs_driven(spec, top, registered):
    """The design inputs a connector table drives: a camera's port bundle (and its colour
    select), a sensor's input pins as bound."""
    if spec.kind == "camera":
        bundle = spec.ports.get("pixels")
        if bundle is None:
            return []  # films only
        channel = _channel_class(registered, bundle)
        color = spec.ports.get("color_sel", getattr(channel, "color_port", None))
        return [f"{bundle}__valid", f"{bundle}__payload", *([color] if color else [])]
    binding = {**top.bindings.get(spec.kind, {}), **spec.ports}
    return [binding[pin] for pin in _input_pins(spec.kind) if binding.get(pin) is not None]


def _channel_class(registered, bundle):
    """The frame-level model of the channel on pixel bundle ``bundle`` of ``registered`` (a
    built-in ``Top``: only those have further-camera channels), or None."""
    where = (registered.frame_channels if registered is not None else {}).get(bundle)
    if where is None:
        return None
    module, name = where
    return getattr(importlib.import_module(module), name)


def _check_servo(scenario, spec, top, registered):
    """A servo's port: in compressed timing an output of one of the design's further-camera
    channels (nothing else runs then), and an output of the servo's 10 bits, signed."""
    port = spec.ports.get("angle") or top.bindings.get("servo", {}).get("angle")
    if port is None:  # it would never move
        raise UsageError(
            f"the servo connector {spec.name!r}: design {top.name!r} drives no servo (it binds "
            f"no output to pin 'angle'); bind one with ports = {{angle = \"PORT\"}} in its "
            "[[robot.actuators]] table, or leave the servo out"
        )
    design = None  # a Verilog design's ports are known once it is built (RealClockLoop)
    if scenario.foreign is None:
        design = _run_ports(scenario, registered)
    if scenario.sim.timing == "compressed":
        channels = registered.frame_channels if registered is not None else {}
        outputs = {
            name for bundle in channels for name in _channel_class(registered, bundle).output_ports
        }
        if port not in outputs:
            # Offer only the outputs that would pass the pin's test below.
            fitting = sorted(
                name
                for name in outputs
                if design is not None and _servo_misfit(spec, top, design, name) is None
            )
            raise UsageError(
                f"the servo connector {spec.name!r}: in compressed timing a servo hears an "
                f"output of a further camera's channel of design {top.name!r}, signed and at "
                f"most 10 bits ({', '.join(fitting) or 'it has none'}), not {port!r}; bind it "
                'to one, or run sim.timing = "real_clock"'
            )
    if design is None:
        return
    ports, _ = design
    if port not in ports:
        raise no_port("servo", spec.name, top, "angle", port, ports)
    misfit = _servo_misfit(spec, top, design, port)
    if misfit is not None:
        raise UsageError(misfit)


def _run_ports(scenario, registered):
    """``(ports, signed)`` of the design as this run builds it: name -> (direction, width),
    and the signed ports' names. A built-in design is built with the run's resolution and
    tables: its resolved spec has the defaults' widths (centroid_x is 8 bits at 160x120, 10
    at 640x480)."""
    if registered is None:
        design = resolve_design(scenario.top, scenario.design_params)
        return design.ports, design.signed
    component = build_component(registered, scenario.params, scenario.design_tables)
    return component_ports(component), signed_ports(component)


def _servo_misfit(spec, top, design, port):
    ports, signed = design
    direction, width = ports[port]
    return port_misfit(
        "servo", spec.name, top, "angle", Port(port, width, direction, port in signed)
    )
