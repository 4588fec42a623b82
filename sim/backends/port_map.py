"""Port maps of foreign Verilog designs: how a design's ports take the world's frames and give
the per-frame outputs (docs/foreign.md). ``load_port_map(path)`` reads and checks a TOML file;
``check_widths(port_map, ports)`` checks it against the widths Verilator reports.

Interface styles: ``stream`` (this project's ``follow_target`` ports) and ``framebuffer``
(per pixel a write enable, a linear write address and a 12-bit RGB444 datum; a one-cycle
new-frame pulse the cycle after the frame's last pixel).

``[connectors.<kind>]`` tables bind the pins of sensor and actuator connectors (an
ultrasound's ``trig``/``echo``, a bumper's ``pressed``) to ports of the design: such a design
runs in real-clock timing on the Verilator pin backend; ``check_connectors`` checks the
bindings against the connector kinds the application knows. A map may leave out the pixel
stream (a design without a camera: connectors, wheels or ``[extra_outputs]`` only).
"""

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, ClassVar

from pydantic import BeforeValidator, Field

from fpga_robotics.hw.errors import UserError

from ...hw.params import FollowTargetParams
from ...hw.pixel import COLOR_SELECT
from ..files import NotTextError, read_user_text
from ..world.schema import Flag, Integer, KeyModel, Text, fail, validate
from .base import BackendError

__all__ = [
    "OUTPUTS",
    "Output",
    "PortMap",
    "PortMapError",
    "check_connector_names",
    "check_connectors",
    "check_widths",
    "follow_target_port_map",
    "load_port_map",
    "parse_port_map",
    "write_follow_target_port_map",
]

#: Per-frame outputs a port map may name: FrameResult field -> (default width, signed).
OUTPUTS = {
    "found": (1, False),
    "proximity": (3, False),
    "centroid_x": (None, False),
    "centroid_leds": (8, False),
    "motor_left": (16, True),
    "motor_right": (16, True),
}
_STYLES = ("stream", "framebuffer")
#: Connector kinds the map binds elsewhere: the camera by ``pixels``/``color``, the wheels by
#: ``outputs.motor_left``/``motor_right``.
_BOUND_ELSEWHERE = {
    "camera": "pixels and color",
    "wheels": "outputs.motor_left and outputs.motor_right",
}
#: Outputs read when the frame's result is ready: they need a pixel stream.
_FRAME_ONLY = ("found", "proximity", "centroid_x", "centroid_leds")
#: At most this many ``[runtime]`` inputs.
MAX_RUNTIME = 8


class PortMapError(UserError, BackendError):
    """A port map that is malformed or does not fit the design."""


@dataclass(frozen=True)
class Output:
    port: str
    width: int | None  # expected width (None: any up to 32)
    signed: bool


@dataclass(frozen=True)
class PortMap:
    top: str
    clock: str
    reset: str | None  # None: the design has no reset (its registers start at their init)
    reset_active_low: bool
    valid: str | None  # None: no pixel stream (a design without a camera)
    payload: str | None  # 14 bits: data[11:0], first[12], last[13]
    data: str | None  # 12-bit RGB444 (with first/last as separate ports)
    first: str | None
    last: str | None
    color_port: str | None
    color_codes: dict  # colour name -> code on color_port
    color_width: int | None
    strobe: str | None  # None: the result is read after_cycles after the frame
    latency: int
    timeout: int
    outputs: dict = field(default_factory=dict)  # FrameResult field -> Output
    filtered_valid: str | None = None
    filtered_payload: str | None = None
    style: str = "stream"
    address: str | None = None  # framebuffer: linear write address y * width + x
    new_frame: str | None = None  # framebuffer: the one-cycle pulse after the last pixel
    after_cycles: int | None = None  # read the outputs this many cycles after the frame
    constants: dict = field(default_factory=dict)  # input port -> value it is tied to
    # input port -> its value until ``ForeignVerilatorBackend.set_runtime`` changes it
    runtime: dict = field(default_factory=dict)
    #: connector kind -> {connector pin: design port} (``[connectors.<kind>]``).
    connectors: dict = field(default_factory=dict)
    #: name -> design output recorded under that name (``[extra_outputs]``; real-clock timing).
    extra_outputs: dict = field(default_factory=dict)
    #: An output of any width whose bits the Verilator frame backend watches on every clock
    #: (``[watch]``): the frame each bit first rises in (``watch_risen``).
    watch: str | None = None

    @property
    def has_pixels(self):
        return self.valid is not None

    def connector_ports(self):
        """Design port -> its key ``connectors.<kind>.<pin>``."""
        return {
            port: f"connectors.{kind}.{pin}"
            for kind, pins in self.connectors.items()
            for pin, port in pins.items()
        }

    def inputs(self):
        """Input port name -> expected width (None: checked elsewhere). Connector ports are
        not listed: their direction is the connector's (``check_connectors``)."""
        ports = {self.clock: 1}
        if self.reset:
            ports[self.reset] = 1
        if not self.has_pixels:
            pass
        elif self.style == "framebuffer":
            ports[self.valid] = 1
            ports[self.address] = None  # wide enough for the frame: checked with its size
            ports[self.data] = 12
            if self.new_frame:
                ports[self.new_frame] = 1
        elif self.payload:
            ports[self.valid] = 1
            ports[self.payload] = 14
        else:
            ports[self.valid] = 1
            ports[self.data] = 12
            for flag in (self.first, self.last):
                if flag:
                    ports[flag] = 1
        if self.color_port:
            ports[self.color_port] = self.color_width
        for name in (*self.constants, *self.runtime):
            ports[name] = None  # any width the value fits: checked with the design's ports
        return ports

    def output_ports(self):
        ports = {self.strobe: 1} if self.strobe else {}
        for out in self.outputs.values():
            ports[out.port] = out.width
        if self.filtered_valid:
            ports[self.filtered_valid] = 1
            ports[self.filtered_payload] = 14
        for port in self.extra_outputs.values():
            ports[port] = None  # any width up to 32
        return ports


# The keys of a port map, each table a model (sim.world.schema) -------------------------------


class _MapKeys(KeyModel):
    """A table of a port map: an unknown key lists the allowed ones; reported first."""

    unknown_first: ClassVar[bool] = True

    @classmethod
    def unknown_key(cls, path, key):
        return f"unknown key '{path}'; allowed: {', '.join(sorted(cls.key_names()))}"

    @classmethod
    def missing_key(cls, path, key, doc):
        return f"missing [{path}]" if doc == "table" else f"missing {path} (a port name)"


def _port_name(value):
    if not isinstance(value, str) or not value.isidentifier():
        fail(f"must be a Verilog port name, got {value!r}")
    return value


#: A Verilog port name.
PortName = Annotated[str, BeforeValidator(_port_name)]


def _table(model, doc=""):
    """A sub-table (``doc="table"``: its absence is reported as ``missing [key]``)."""
    return Annotated[model, Field(description=doc)]


def _ports_of(what, value_check=None):
    """A table ``name = value`` of ports (``[constants]``, ``[runtime]``)."""

    def check(table):
        if not isinstance(table, dict):
            fail("must be a table")
        for name, value in table.items():
            if not name.isidentifier():
                fail("not a port name", sub=f".{name}:")
            if value_check is not None:
                value_check(value, name)
        return dict(table)

    return Annotated[object, BeforeValidator(check), Field(description=what)]


def _level(note):
    def check(value, name):
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            fail(f"must be an integer >= 0{note}, got {value!r}", sub=f".{name}")

    return check


def _extra_outputs(table):
    if not isinstance(table, dict):
        fail("must be a table")
    for name, port in table.items():
        if not name.isidentifier() or name in OUTPUTS:
            fail(
                "the name must be a Python name other than the [outputs] keys",
                sub=f".{name}:",
            )
        if not isinstance(port, str) or not port.isidentifier():
            fail(f"must be a Verilog port name, got {port!r}", sub=f".{name}")
    return dict(table)


def _connector_tables(table):
    """``[connectors.<kind>]``: kind -> {pin: port}; names only (the kinds and their pins are
    checked by ``check_connectors``)."""
    if not isinstance(table, dict):
        fail("must be a table")
    for kind, pins in table.items():
        if not kind.isidentifier():
            fail("not a connector kind", sub=f".{kind}:")
        if kind in _BOUND_ELSEWHERE:
            fail(
                f"the {kind} is bound by {_BOUND_ELSEWHERE[kind]}, not a [connectors] table",
                sub=f".{kind}:",
            )
        if not isinstance(pins, dict) or not pins:
            fail('must be a table of pin = "port"', sub=f".{kind}")
        for pin, port in pins.items():
            if not isinstance(port, str) or not port.isidentifier():
                fail(f"must be a Verilog port name, got {port!r}", sub=f".{kind}.{pin}")
    return {kind: dict(pins) for kind, pins in table.items()}


def _codes(codes):
    if not isinstance(codes, dict) or not codes:
        fail("must be a table of colour = code")
    for name, code in codes.items():
        if name not in COLOR_SELECT:
            fail(f"unknown colour {name!r}; known: {', '.join(COLOR_SELECT)}", sub=":")
        if isinstance(code, bool) or not isinstance(code, int) or code < 0:
            fail("must be an integer >= 0", sub=f".{name}")
    return dict(codes)


def _top_name(value):
    if not isinstance(value, str) or not value.isidentifier():
        fail(f"must be the top module's name, got {value!r}")
    return value


class ClockKeys(_MapKeys):
    port: PortName


class WatchKeys(_MapKeys):
    port: PortName


class ResetKeys(_MapKeys):
    port: PortName = None  # required when [reset] is given
    active_low: Flag(style="scenario") = False


class StreamPixelKeys(_MapKeys):
    """``payload`` (14 bits: data, first, last) or ``data`` (12-bit RGB444, with optional
    ``first``/``last`` flags)."""

    valid: PortName
    payload: PortName = None
    data: PortName = None
    first: PortName = None
    last: PortName = None


class FramebufferPixelKeys(_MapKeys):
    write_enable: PortName
    address: PortName
    data: PortName
    new_frame: PortName = None


class ColorKeys(_MapKeys):
    port: PortName = None
    width: Integer(ge=1, le=32) = None
    codes: Annotated[object, BeforeValidator(_codes)] = None  # None: the project's codes


class ResultKeys(_MapKeys):
    """``strobe`` (with ``latency``) or ``after_cycles``."""

    strobe: PortName = None
    latency: Integer(ge=0, le=1 << 20) = None  # None: 0
    timeout: Integer(ge=1, le=1 << 30) = 100_000
    after_cycles: Integer(ge=1, le=1 << 20) = None


class OutputKeys(_MapKeys):
    port: PortName
    width: Integer(ge=1, le=32) = None  # None: the output's default (OUTPUTS)
    signed: Flag(style="scenario") = None


def _output(value):
    if isinstance(value, str):
        return {"port": value}
    if not isinstance(value, dict):
        fail("must be a port name or a table")
    return value


_Output = Annotated[OutputKeys, BeforeValidator(_output)]


class OutputsKeys(_MapKeys):
    found: _Output = None
    proximity: _Output = None
    centroid_x: _Output = None
    centroid_leds: _Output = None
    motor_left: _Output = None
    motor_right: _Output = None


class FilteredKeys(_MapKeys):
    valid: PortName
    payload: PortName


class PortMapKeys(_MapKeys):
    """A port map file. ``pixels`` is read by the style's model (``StreamPixelKeys`` or
    ``FramebufferPixelKeys``); the relations between tables are checked by
    ``parse_port_map``."""

    style: Text(choices=_STYLES, style="scenario") = "stream"
    top: Annotated[str, BeforeValidator(_top_name)] = None
    clock: _table(ClockKeys, "table")
    reset: _table(ResetKeys) = None  # no [reset]: the design has none
    pixels: Annotated[object, Field(description="table")] = None
    color: _table(ColorKeys) = None
    result: _table(ResultKeys) = None
    outputs: _table(OutputsKeys) = None
    filtered: _table(FilteredKeys) = None
    # Inputs the world does not drive (a read address of a debug port, a mode pin) tied to
    # a value.
    constants: _ports_of("input port = value", _level("")) = Field(default_factory=dict)
    # Inputs held at a value the host sets between frames (a mutant select, a mode).
    runtime: _ports_of("input port = initial value", _level(" (its initial value)")) = Field(
        default_factory=dict
    )
    connectors: Annotated[object, BeforeValidator(_connector_tables)] = Field(default_factory=dict)
    extra_outputs: Annotated[object, BeforeValidator(_extra_outputs)] = Field(default_factory=dict)
    # An output whose bits are watched on every clock (a mutant netlist's ``mutinf``).
    watch: _table(WatchKeys) = None


assert OUTPUTS.keys() == OutputsKeys.model_fields.keys()


def _error(message):
    return PortMapError(f"port map: {message}")


def parse_port_map(data):
    """A ``PortMap`` from the TOML document ``data`` (a dict); ``PortMapError`` if invalid."""
    if isinstance(data, dict) and "top" not in data:
        data = {**data, "top": None}  # reported as "top must be the top module's name"
    k = validate(PortMapKeys, data, "", _error)
    style, connectors = k.style, k.connectors
    reset = k.reset if k.reset is not None else ResetKeys()
    if k.reset is not None and k.reset.port is None:
        raise _error("missing reset.port (a port name)")

    # A design without a camera (connectors, wheels or recorded outputs only) has no pixel
    # stream; a map with none of these names nothing the design does.
    if k.pixels is None and not connectors and k.outputs is None and not k.extra_outputs:
        raise _error("missing [pixels]")
    address = new_frame = payload = first = last = valid = data_port = None
    if not k.pixels:
        for key in ("color", "result", "filtered"):
            if key in data:
                raise _error(
                    f"[{key}] goes with a pixel stream; this map has "
                    "no pixels (a design without a camera)"
                )
    elif style == "framebuffer":
        pixels = validate(FramebufferPixelKeys, k.pixels, "pixels", _error)
        valid, address, data_port = pixels.write_enable, pixels.address, pixels.data
        new_frame = pixels.new_frame
    else:
        pixels = validate(StreamPixelKeys, k.pixels, "pixels", _error)
        valid, payload, data_port = pixels.valid, pixels.payload, pixels.data
        if (payload is None) == (data_port is None):
            raise _error(
                "give pixels.payload (14 bits with the first/last "
                "flags) or pixels.data (12-bit RGB444), not both or neither"
            )
        first, last = pixels.first, pixels.last
        if payload is not None and (first or last):
            raise _error("pixels.first/last go with pixels.data, not with payload")

    color = k.color if k.color is not None else ColorKeys()
    codes = color.codes if color.codes is not None else dict(COLOR_SELECT)

    result = k.result
    if result is None:
        if k.pixels:
            raise _error("missing [result]")
        result = ResultKeys()
    if result.after_cycles is not None:
        if result.strobe is not None or result.latency is not None:
            raise _error("give result.strobe (and latency) or result.after_cycles, not both")
    elif k.pixels and result.strobe is None:
        raise _error("missing result.strobe (a port name)")

    outputs = {}
    for key, value in k.outputs or OutputsKeys():
        if value is None:
            continue
        default_width, default_signed = OUTPUTS[key]
        outputs[key] = Output(
            value.port,
            default_width if value.width is None else value.width,
            default_signed if value.signed is None else value.signed,
        )
    extra = k.extra_outputs
    if not outputs and not extra and not connectors:
        raise _error("[outputs] names no output")
    if not k.pixels:
        frame_only = [key for key in _FRAME_ONLY if key in outputs]
        if frame_only:
            raise _error(
                f"outputs.{frame_only[0]} is read when a frame's "
                "result is ready: it needs a pixel stream (pixels)"
            )
    filtered = k.filtered
    if len(k.runtime) > MAX_RUNTIME:
        raise _error(f"[runtime] names {len(k.runtime)} inputs (at most {MAX_RUNTIME})")
    port_map = PortMap(
        top=k.top,
        clock=k.clock.port,
        reset=reset.port,
        reset_active_low=reset.active_low,
        valid=valid,
        payload=payload,
        data=data_port,
        first=first,
        last=last,
        color_port=color.port,
        color_codes=codes,
        color_width=color.width,
        strobe=result.strobe,
        latency=result.latency or 0,
        timeout=result.timeout,
        outputs=outputs,
        filtered_valid=filtered.valid if filtered else None,
        filtered_payload=filtered.payload if filtered else None,
        style=style,
        address=address,
        new_frame=new_frame,
        after_cycles=result.after_cycles,
        constants=k.constants,
        runtime=k.runtime,
        connectors=connectors,
        extra_outputs=extra,
        watch=k.watch.port if k.watch is not None else None,
    )
    pm = port_map
    names = [
        n
        for n in (
            pm.clock,
            pm.reset,
            pm.valid,
            pm.payload,
            pm.data,
            pm.first,
            pm.last,
            pm.address,
            pm.new_frame,
            pm.color_port,
            pm.strobe,
            *(o.port for o in pm.outputs.values()),
            pm.filtered_valid,
            pm.filtered_payload,
            *pm.constants,
            *pm.runtime,
            *pm.extra_outputs.values(),
            pm.watch,
            *(p for pins in pm.connectors.values() for p in pins.values()),
        )
        if n
    ]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise _error(f"port {dup[0]!r} is mapped more than once")
    return port_map


def load_port_map(path):
    """Read and check the TOML port map at ``path``."""
    if not str(path).strip():  # Path("") would read the current folder
        raise PortMapError("the port map's path is empty; give its PORTS.toml file")
    path = Path(path)
    try:
        text = read_user_text(path)
    except OSError as exc:
        raise PortMapError(f"cannot read the port map {path}: {exc.strerror or exc}") from None
    except NotTextError as exc:
        raise PortMapError(f"cannot read the port map {path}: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise PortMapError(f"port map {path}: not valid TOML: {exc}") from None
    return parse_port_map(data)


def check_widths(port_map, ports, pixels=None):
    """Check ``port_map`` against the design's ``ports`` (name -> (direction, width, signed)
    as Verilator reports them) for frames of ``pixels`` pixels; ``PortMapError`` names the
    first problem."""
    for direction, wanted in (("input", port_map.inputs()), ("output", port_map.output_ports())):
        for name, width in wanted.items():
            if name not in ports:
                raise PortMapError(
                    f"port map: the design {port_map.top} has no port {name!r} "
                    f"(its ports: {', '.join(ports)})"
                )
            actual_dir, actual_width, _ = ports[name]
            if actual_dir != direction:
                raise PortMapError(
                    f"port map: port {name!r} of {port_map.top} is an "
                    f"{actual_dir}, the map uses it as an {direction}"
                )
            if width is not None and actual_width != width:
                raise PortMapError(
                    f"port map: port {name!r} of {port_map.top} is "
                    f"{actual_width} bits wide, the map expects {width}"
                )
            if actual_width > 32:
                raise PortMapError(
                    f"port map: port {name!r} is {actual_width} bits wide (at most 32)"
                )
    if port_map.watch is not None:
        actual = ports.get(port_map.watch)
        if actual is None or actual[0] != "output":
            raise PortMapError(
                f"port map: watch.port {port_map.watch!r} must be an output of "
                f"{port_map.top} (its ports: {', '.join(ports)})"
            )
    if port_map.address and pixels is not None:
        width = ports[port_map.address][1]
        if (pixels - 1) >> width:
            raise PortMapError(
                f"port map: the {width}-bit address port {port_map.address!r} "
                f"cannot address {pixels} pixels"
            )
    if port_map.color_port:
        width = ports[port_map.color_port][1]
        too_big = [n for n, c in port_map.color_codes.items() if c >= 1 << width]
        if too_big:
            raise PortMapError(
                f"port map: color.codes.{too_big[0]} does not fit the "
                f"{width}-bit port {port_map.color_port!r}"
            )
    for table, values in (("constants", port_map.constants), ("runtime", port_map.runtime)):
        for name, value in values.items():
            if value >> ports[name][1]:
                raise PortMapError(
                    f"port map: {table}.{name} = {value} does not fit the {ports[name][1]}-bit port"
                )
    for port, key in port_map.connector_ports().items():
        if port not in ports:
            raise PortMapError(
                f"port map: {key}: the design {port_map.top} has no port "
                f"{port!r} (its ports: {', '.join(ports)})"
            )
        if ports[port][1] > 32:
            raise PortMapError(
                f"port map: {key}: port {port!r} is {ports[port][1]} bits wide (at most 32)"
            )
    mapped = {**port_map.inputs(), **port_map.connector_ports()}
    unconnected = [n for n, (d, _, _) in ports.items() if d == "input" and n not in mapped]
    if unconnected:
        raise PortMapError(
            f"port map: input {unconnected[0]!r} of {port_map.top} is not "
            "mapped (every input must be driven)"
        )


def check_connector_names(port_map, kinds):
    """Check that ``port_map``'s ``[connectors]`` name connector ``kinds`` the application
    knows and their pins (``check_connectors``' first checks; no design needed)."""
    for kind, pins in port_map.connectors.items():
        if kind not in kinds:
            raise PortMapError(
                f"port map: connectors.{kind}: unknown connector kind; known: "
                f"{', '.join(sorted(kinds))}"
            )
        for pin in pins:
            if pin not in kinds[kind]:
                raise PortMapError(
                    f"port map: connectors.{kind}.{pin}: the {kind} connector has no pin "
                    f"{pin!r}; its pins: {', '.join(kinds[kind])}"
                )


def check_connectors(port_map, ports, kinds):
    """Check ``port_map``'s ``[connectors]`` against the design's ``ports`` (as for
    ``check_widths``) and the connector ``kinds`` the application knows: kind -> {pin: (direction
    seen from the design, "in" or "out"; at most this many bits)}. ``PortMapError`` names the
    key of the first problem."""
    check_connector_names(port_map, kinds)
    for kind, pins in port_map.connectors.items():
        known = kinds[kind]
        for pin, port in pins.items():
            key = f"connectors.{kind}.{pin}"
            if port not in ports:
                raise PortMapError(
                    f"port map: {key}: the design {port_map.top} has no port "
                    f"{port!r} (its ports: {', '.join(ports)})"
                )
            direction, width = known[pin]
            wanted = {"in": "input", "out": "output"}[direction]
            actual_dir, actual_width, _ = ports[port]
            if actual_dir != wanted:
                raise PortMapError(
                    f"port map: {key}: port {port!r} of {port_map.top} is an "
                    f"{actual_dir}; the {kind} pin {pin!r} needs an {wanted}"
                )
            if actual_width > width:
                raise PortMapError(
                    f"port map: {key}: port {port!r} of {port_map.top} is "
                    f"{actual_width} bits wide; the {kind} pin {pin!r} takes "
                    + (f"{width} bit" if width == 1 else f"at most {width} bits")
                )


#: The port map of the exported ``follow_target`` (docs/foreign.md).
_FOLLOW_TARGET_MAP = """\
# Port map of the exported follow_target (python -m fpga_robotics.export), stream style.
style = "stream"
top = "follow_target"
clock = {{ port = "clk" }}
reset = {{ port = "rst", active_low = false }}
pixels = {{ valid = "pixels__valid", payload = "pixels__payload" }}
color = {{ port = "color_sel" }}  # this project's 3-bit codes (docs/contract.md)
result = {{ strobe = "frame_done", latency = {latency}, timeout = 100000 }}
filtered = {{ valid = "filtered__valid", payload = "filtered__payload" }}

[outputs]
found = "found"
proximity = "proximity"
centroid_x = "centroid_x"
centroid_leds = "centroid_leds"
motor_left = {{ port = "motor_left", width = 16, signed = true }}
motor_right = {{ port = "motor_right", width = 16, signed = true }}
"""


def follow_target_port_map(params=None):
    """TOML text: the port map of the exported ``follow_target`` at ``params``."""
    params = params if params is not None else FollowTargetParams()
    return _FOLLOW_TARGET_MAP.format(latency=params.motor_latency)


def write_follow_target_port_map(path, params=None):
    """Write ``follow_target_port_map(params)`` to ``path``, never replacing a file;
    ``PortMapError`` when it cannot be written."""
    try:
        with open(path, "x") as f:
            f.write(follow_target_port_map(params))
    except OSError as exc:
        raise PortMapError(f"cannot write {path}: {exc.strerror or exc}") from None
