"""Port maps of foreign Verilog designs: how a design's ports take the world's frames and give
the per-frame outputs (docs/foreign.md). ``load_port_map(path)`` reads and checks a TOML file;
``check_widths(port_map, ports)`` checks it against the widths Verilator reports.

Interface styles: ``stream`` (this project's ``follow_target`` ports) and ``framebuffer``
(per pixel a write enable, a linear write address and a 12-bit RGB444 datum; a one-cycle
new-frame pulse the cycle after the frame's last pixel).

``[connectors.<kind>]`` tables bind the pins of sensor and actuator connectors (an
ultrasound's ``trig``/``echo``, a bumper's ``pressed``) to ports of the design: such a design
runs in real-clock timing on the Verilator pin backend; ``check_connectors`` checks the
bindings against the connector kinds the application knows. A map with connectors may leave
out the pixel stream (a design without a camera).
"""

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from fpga_robotics.hw.errors import UserError

from ...hw.params import FollowTargetParams
from ...hw.pixel import COLOR_SELECT
from .base import BackendError

__all__ = [
    "OUTPUTS",
    "Output",
    "PortMap",
    "PortMapError",
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
_TOP_KEYS = {
    "style",
    "top",
    "clock",
    "reset",
    "pixels",
    "color",
    "result",
    "outputs",
    "filtered",
    "constants",
    "runtime",
    "connectors",
    "extra_outputs",
}
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


def _table(data, key, where, required=True):
    value = data.get(key)
    if value is None:
        if required:
            raise PortMapError(f"port map: missing [{key}]{where}")
        return {}
    if not isinstance(value, dict):
        raise PortMapError(f"port map: {key} must be a table")
    return value


def _name(table, key, where, required=True):
    value = table.get(key)
    if value is None:
        if required:
            raise PortMapError(f"port map: missing {where}.{key} (a port name)")
        return None
    if not isinstance(value, str) or not value.isidentifier():
        raise PortMapError(f"port map: {where}.{key} must be a Verilog port name, got {value!r}")
    return value


def _unknown(table, allowed, where):
    extra = sorted(set(table) - set(allowed))
    if extra:
        raise PortMapError(
            f"port map: unknown key '{where}{extra[0]}'; allowed: {', '.join(sorted(allowed))}"
        )


def _int(table, key, where, default, low, high):
    value = table.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise PortMapError(
            f"port map: {where}.{key} must be an integer in {low}..{high}, got {value!r}"
        )
    return value


def parse_port_map(data):
    """A ``PortMap`` from the TOML document ``data`` (a dict); ``PortMapError`` if invalid."""
    _unknown(data, _TOP_KEYS, "")
    style = data.get("style", "stream")
    if style not in _STYLES:
        raise PortMapError(f"port map: style must be one of {', '.join(_STYLES)}, got {style!r}")
    top = data.get("top")
    if not isinstance(top, str) or not top.isidentifier():
        raise PortMapError(f"port map: top must be the top module's name, got {top!r}")

    clock = _table(data, "clock", "")
    _unknown(clock, {"port"}, "clock.")
    # No [reset]: a design without one (its registers start at their initial values).
    reset = _table(data, "reset", "", required=False)
    _unknown(reset, {"port", "active_low"}, "reset.")
    active_low = reset.get("active_low", False)
    if not isinstance(active_low, bool):
        raise PortMapError("port map: reset.active_low must be true or false")

    connectors = _connectors(data)
    # A design without a camera (only connectors and wheels) has no pixel stream.
    pixels = _table(data, "pixels", "", required=not connectors)
    address = new_frame = payload = first = last = valid = data_port = None
    if not pixels:
        for key in ("color", "result", "filtered"):
            if key in data:
                raise PortMapError(
                    f"port map: [{key}] goes with a pixel stream; this map has "
                    "no pixels (a design without a camera)"
                )
    elif style == "framebuffer":
        _unknown(pixels, {"write_enable", "address", "data", "new_frame"}, "pixels.")
        valid = _name(pixels, "write_enable", "pixels")
        address = _name(pixels, "address", "pixels")
        data_port = _name(pixels, "data", "pixels")
        new_frame = _name(pixels, "new_frame", "pixels", required=False)
    else:
        _unknown(pixels, {"valid", "payload", "data", "first", "last"}, "pixels.")
        valid = _name(pixels, "valid", "pixels")
        payload = _name(pixels, "payload", "pixels", required=False)
        data_port = _name(pixels, "data", "pixels", required=False)
        if (payload is None) == (data_port is None):
            raise PortMapError(
                "port map: give pixels.payload (14 bits with the first/last "
                "flags) or pixels.data (12-bit RGB444), not both or neither"
            )
        first = _name(pixels, "first", "pixels", required=False)
        last = _name(pixels, "last", "pixels", required=False)
        if payload is not None and (first or last):
            raise PortMapError("port map: pixels.first/last go with pixels.data, not with payload")

    color = _table(data, "color", "", required=False)
    _unknown(color, {"port", "width", "codes"}, "color.")
    color_port = _name(color, "port", "color", required=False)
    codes = color.get("codes")
    if codes is None:
        codes = dict(COLOR_SELECT)
    if not isinstance(codes, dict) or not codes:
        raise PortMapError("port map: color.codes must be a table of colour = code")
    for name, code in codes.items():
        if name not in COLOR_SELECT:
            raise PortMapError(
                f"port map: color.codes: unknown colour {name!r}; known: {', '.join(COLOR_SELECT)}"
            )
        if isinstance(code, bool) or not isinstance(code, int) or code < 0:
            raise PortMapError(f"port map: color.codes.{name} must be an integer >= 0")
    color_width = color.get("width")
    if color_width is not None:
        color_width = _int(color, "width", "color", None, 1, 32)

    result = _table(data, "result", "", required=bool(pixels))
    _unknown(result, {"strobe", "latency", "timeout", "after_cycles"}, "result.")
    strobe = _name(
        result, "strobe", "result", required=bool(pixels) and "after_cycles" not in result
    )
    after_cycles = None
    if "after_cycles" in result:
        if strobe is not None or "latency" in result:
            raise PortMapError(
                "port map: give result.strobe (and latency) or result.after_cycles, not both"
            )
        after_cycles = _int(result, "after_cycles", "result", None, 1, 1 << 20)
    latency = _int(result, "latency", "result", 0, 0, 1 << 20)
    timeout = _int(result, "timeout", "result", 100_000, 1, 1 << 30)

    out_table = _table(data, "outputs", "", required=False)
    _unknown(out_table, set(OUTPUTS), "outputs.")
    outputs = {}
    for key, value in out_table.items():
        default_width, default_signed = OUTPUTS[key]
        if isinstance(value, str):
            value = {"port": value}
        if not isinstance(value, dict):
            raise PortMapError(f"port map: outputs.{key} must be a port name or a table")
        _unknown(value, {"port", "width", "signed"}, f"outputs.{key}.")
        port = _name(value, "port", f"outputs.{key}")
        width = value.get("width", default_width)
        if width is not None:
            width = _int({"width": width}, "width", f"outputs.{key}", None, 1, 32)
        signed = value.get("signed", default_signed)
        if not isinstance(signed, bool):
            raise PortMapError(f"port map: outputs.{key}.signed must be true or false")
        outputs[key] = Output(port, width, signed)
    extra = _table(data, "extra_outputs", "", required=False)
    for name, port in extra.items():
        if not name.isidentifier() or name in OUTPUTS:
            raise PortMapError(
                f"port map: extra_outputs.{name}: the name must be a Python "
                f"name other than the [outputs] keys"
            )
        _name(extra, name, "extra_outputs")
    if not outputs and not extra and not connectors:
        raise PortMapError("port map: [outputs] names no output")
    if not pixels:
        frame_only = [k for k in _FRAME_ONLY if k in outputs]
        if frame_only:
            raise PortMapError(
                f"port map: outputs.{frame_only[0]} is read when a frame's "
                "result is ready: it needs a pixel stream (pixels)"
            )

    filtered = _table(data, "filtered", "", required=False)
    _unknown(filtered, {"valid", "payload"}, "filtered.")
    f_valid = _name(filtered, "valid", "filtered", required=bool(filtered))
    f_payload = _name(filtered, "payload", "filtered", required=bool(filtered))

    # Inputs the world does not drive (a read address of a debug port, a mode pin) tied to a
    # value: [constants] port = value.
    constants = _table(data, "constants", "", required=False)
    for name, value in constants.items():
        if not name.isidentifier():
            raise PortMapError(f"port map: constants.{name}: not a port name")
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise PortMapError(f"port map: constants.{name} must be an integer >= 0, got {value!r}")
    # Inputs held at a value the host sets between frames (a mutant select, a mode):
    # [runtime] port = initial value.
    runtime = _table(data, "runtime", "", required=False)
    if len(runtime) > MAX_RUNTIME:
        raise PortMapError(
            f"port map: [runtime] names {len(runtime)} inputs (at most {MAX_RUNTIME})"
        )
    for name, value in runtime.items():
        if not name.isidentifier():
            raise PortMapError(f"port map: runtime.{name}: not a port name")
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise PortMapError(
                f"port map: runtime.{name} must be an integer >= 0 (its "
                f"initial value), got {value!r}"
            )
    port_map = PortMap(
        top=top,
        clock=_name(clock, "port", "clock"),
        reset=_name(reset, "port", "reset", required=bool(reset)),
        reset_active_low=active_low,
        valid=valid,
        payload=payload,
        data=data_port,
        first=first,
        last=last,
        color_port=color_port,
        color_codes=codes,
        color_width=color_width,
        strobe=strobe,
        latency=latency,
        timeout=timeout,
        outputs=outputs,
        filtered_valid=f_valid,
        filtered_payload=f_payload,
        style=style,
        address=address,
        new_frame=new_frame,
        after_cycles=after_cycles,
        constants=dict(constants),
        runtime=dict(runtime),
        connectors=connectors,
        extra_outputs=dict(extra),
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
            *(p for pins in pm.connectors.values() for p in pins.values()),
        )
        if n
    ]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise PortMapError(f"port map: port {dup[0]!r} is mapped more than once")
    return port_map


def _connectors(data):
    """``[connectors.<kind>]`` tables: kind -> {pin: port}; names only (the kinds and their
    pins are checked by ``check_connectors``)."""
    table = _table(data, "connectors", "", required=False)
    out = {}
    for kind, pins in table.items():
        where = f"connectors.{kind}"
        if not kind.isidentifier():
            raise PortMapError(f"port map: {where}: not a connector kind")
        if kind in _BOUND_ELSEWHERE:
            raise PortMapError(
                f"port map: {where}: the {kind} is bound by "
                f"{_BOUND_ELSEWHERE[kind]}, not a [connectors] table"
            )
        if not isinstance(pins, dict) or not pins:
            raise PortMapError(f'port map: {where} must be a table of pin = "port"')
        for pin in pins:
            _name(pins, pin, where)
        out[kind] = dict(pins)
    return out


def load_port_map(path):
    """Read and check the TOML port map at ``path``."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise PortMapError(f"cannot read the port map {path}: {exc.strerror or exc}") from None
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


def check_connectors(port_map, ports, kinds):
    """Check ``port_map``'s ``[connectors]`` against the design's ``ports`` (as for
    ``check_widths``) and the connector ``kinds`` the application knows: kind -> {pin: (direction
    seen from the design, "in" or "out"; at most this many bits)}. ``PortMapError`` names the
    key of the first problem."""
    for kind, pins in port_map.connectors.items():
        if kind not in kinds:
            raise PortMapError(
                f"port map: connectors.{kind}: unknown connector kind; known: "
                f"{', '.join(sorted(kinds))}"
            )
        known = kinds[kind]
        for pin, port in pins.items():
            key = f"connectors.{kind}.{pin}"
            if pin not in known:
                raise PortMapError(
                    f"port map: {key}: the {kind} connector has no pin {pin!r}; "
                    f"its pins: {', '.join(known)}"
                )
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
