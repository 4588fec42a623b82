"""``PinDesignSource``: a design for the pin backends, its ports and its generated sources.

The ports are read from the component's signature and named as the generated Verilog and
CXXRTL name them: a member path joined with ``__`` (``pixels.valid`` is ``pixels__valid``).
The clock ``clk`` and the reset ``rst`` are Amaranth's defaults and not ports here.
"""

import collections
import contextlib
import functools

from amaranth.hdl import Fragment
from amaranth.lib import wiring

from ...hw.params import FollowTargetParams
from ...hw.top import FollowTarget
from ...hw.verilog import generate_cxxrtl, generate_verilog, verilog_ports
from .base import PinError, Port

__all__ = [
    "FILTERED_PORTS",
    "PIXEL_PORTS",
    "PinDesignSource",
    "follow_target_source",
    "kept_source",
]

#: The default stream bindings: (valid, payload) of the pixel input and the filtered output.
PIXEL_PORTS = ("pixels__valid", "pixels__payload")
FILTERED_PORTS = ("filtered__valid", "filtered__payload")
#: Width of a framed pixel payload: data[11:0], first[12], last[13] (docs/contract.md).
PAYLOAD_BITS = 14
#: Ports per design the compiled drivers address by one bit of a 64-bit mask.
MAX_PORTS = 64
#: Design sources ``kept_source`` keeps per process: key -> (owner, PinDesignSource).
_KEPT = collections.OrderedDict()
_KEPT_MAX = 16


class PinDesignSource:
    """A design for ``get_pin_backend``.

    Parameters
    ----------
    factory : callable
        Returns a fresh ``wiring.Component`` (called for each simulator and generated source).
    key : str
        Names the design in the build cache (with a hash of the generated source).
    pixels : (str, str), optional
        The (valid, payload) input ports ``stream_frame`` drives, e.g. ``PIXEL_PORTS``.
    filtered : (str, str), optional
        The (valid, payload) output ports captured into ``filtered_frame``.
    frame_size : (int, int), optional
        (width, height) of the frames; needed with ``pixels``.
    """

    def __init__(self, factory, key, *, pixels=None, filtered=None, frame_size=None):
        if not callable(factory):
            raise TypeError("factory must be a callable returning a wiring.Component")
        if not isinstance(key, str) or not key.replace("_", "").replace("-", "").isalnum():
            raise PinError(f"design key {key!r} must be letters, digits, '_' or '-'")
        self.factory = factory
        self.key = key
        component = factory()
        if not isinstance(component, wiring.Component):
            raise TypeError(f"the factory returned {component!r}, not a wiring.Component")
        # Handed out by the first component() call: an Amaranth elaboratable that is created
        # and never elaborated warns when it is collected.
        self._unused = component
        try:
            self._read_ports(component, pixels, filtered, frame_size)
        except PinError:
            self._discard()
            raise

    def _discard(self):
        """Elaborate the unused component, so that dropping it does not warn."""
        component, self._unused = self._unused, None
        with contextlib.suppress(Exception):
            Fragment.get(component, None)

    def _read_ports(self, component, pixels, filtered, frame_size):
        key = self.key
        ports = {}
        for name, (value, direction) in verilog_ports(component).items():
            shape = value.shape()
            ports[name] = Port(name, shape.width, "in" if direction == "i" else "out", shape.signed)
        taken = [name for name in ("clk", "rst") if name in ports]
        if taken:
            raise PinError(
                f"design {key!r} has a port named {taken[0]!r}, the name of the "
                f"clock domain's own {'clock' if taken[0] == 'clk' else 'reset'}; "
                "rename the port"
            )
        if len(ports) > MAX_PORTS:
            raise PinError(
                f"design {key!r} has {len(ports)} ports; the pin backends take at most {MAX_PORTS}"
            )
        wide = [p.name for p in ports.values() if p.width > 64]
        if wide:
            raise PinError(f"ports wider than 64 bits are not supported: {', '.join(wide)}")
        #: name -> Port, in signature order.
        self.ports = ports
        self.pixels = self._binding(pixels, "in", "pixels")
        self.filtered = self._binding(filtered, "out", "filtered")
        if (self.pixels or self.filtered) and frame_size is None:
            raise PinError("a pixel stream binding needs frame_size=(width, height)")
        if frame_size is not None:
            width, height = frame_size
            if not (
                isinstance(width, int) and isinstance(height, int) and width >= 1 and height >= 1
            ):
                raise PinError(f"frame_size must be two positive ints, not {frame_size!r}")
            frame_size = (width, height)
        self.frame_size = frame_size

    def _binding(self, names, direction, what):
        if names is None:
            return None
        valid, payload = names
        for name, width in ((valid, 1), (payload, PAYLOAD_BITS)):
            port = self.ports.get(name)
            if port is None or port.direction != direction or port.width != width:
                raise PinError(
                    f"the {what} binding needs a {width}-bit {direction}put port "
                    f"{name!r}; the design's ports: {', '.join(self.ports)}"
                )
        return (valid, payload)

    def component(self):
        """A component to elaborate (the one the ports were read from, the first time)."""
        component, self._unused = self._unused, None
        return self.factory() if component is None else component

    @functools.cached_property
    def verilog(self):
        """Verilog text, top module ``follow_target`` (the name every flow here uses)."""
        return generate_verilog(component=self.component())

    @functools.cached_property
    def cxxrtl(self):
        """CXXRTL C++ text, top class ``p_follow__target``."""
        return generate_cxxrtl(self.component())

    def __repr__(self):
        return f"PinDesignSource({self.key!r}, {len(self.ports)} ports)"


def kept_source(key, owner, make):
    """The ``PinDesignSource`` ``make()`` returns for design ``key``, kept per process while
    the design is built from the same ``owner`` (its ``Top``): its generated Verilog and
    CXXRTL (Amaranth and Yosys, about a second) then serve every later run of the design,
    as the frame backends' sources do. ``key`` must name everything else the design is
    built from (its parameters and tables)."""
    kept = _KEPT.get(key)
    if kept is not None and kept[0] is owner:
        _KEPT.move_to_end(key)
        return kept[1]
    source = make()
    _KEPT[key] = (owner, source)
    if len(_KEPT) > _KEPT_MAX:
        _KEPT.popitem(last=False)
    return source


def follow_target_source(params=None):
    """``FollowTarget(params)`` (hw/top.py) as a ``PinDesignSource``, its pixel and filtered
    streams bound."""
    params = FollowTargetParams() if params is None else params
    return PinDesignSource(
        lambda: FollowTarget(params),
        f"follow_target_{params.width}x{params.height}",
        pixels=PIXEL_PORTS,
        filtered=FILTERED_PORTS,
        frame_size=(params.width, params.height),
    )
