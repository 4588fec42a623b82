"""The pin-level interface to a design: every input and output port by name, driven and
watched clock by clock, for designs whose timing is measured in cycles of world time (an
ultrasound echo counted at 50 MHz, a line sensor's edge) rather than in frames.

Cycle numbering, shared by every pin backend so that they agree bit for bit:

- After ``reset()`` the design is in its power-on state and ``cycle`` is 0.
- ``run(n)`` performs rising edges ``cycle + 1`` .. ``cycle + n`` (fewer if it stops early).
  Before edge ``e`` every input holds the last value given for an edge ``<= e``: by
  ``poke`` (which takes effect at edge ``cycle + 1``), by ``schedule(e', ...)`` with
  ``e' <= e``, or by the pixel stream (below). Edge ``e`` samples them.
- After each edge the design settles; if a watched output then differs from its value
  before that edge, ``run`` stops and returns ``Stop(cycle=e, port=name, value=new)``
  (with several, the first in ``watch`` order); ``cycle`` is then ``e``.
- ``peek(name)`` is a port's settled value now (after edge ``cycle``, with the inputs of
  edge ``cycle + 1`` applied where the design has a combinational path); signed ports are
  returned as negative Python ints.

A pixel stream (``stream_frame``) presents one frame's pixels on the design's stream ports:
pixel ``(y, x)`` is valid for edge ``timing.start + y * timing.line_period + x *
timing.pixel_period`` with its ``first``/``last`` flags, and ``valid`` is low on every other
edge. Where the design has a filtered output stream, each valid beat is captured in order
into ``filtered_frame()``.
"""

from abc import ABC, abstractmethod
from dataclasses import dataclass

from fpga_robotics.hw.errors import UserError

__all__ = [
    "DesignError",
    "DesignStopped",
    "PinBackend",
    "PinError",
    "PixelTiming",
    "Port",
    "ShadowDesignError",
    "Stop",
    "StopLimit",
]


class PinError(UserError, RuntimeError):
    """A pin-level run cannot go on: unknown port, a value out of range, a missing tool."""


class DesignError(PinError):
    """The design itself ended a run: it called ``$finish``, ``$stop`` or ``$fatal``
    (``DesignStopped``), or its result strobe never rose (the real-clock loop)."""


class ShadowDesignError(DesignError):
    """The shadow design, not the primary, ended the run (real-clock timing)."""


class DesignStopped(DesignError):
    """The design called ``$finish``, ``$stop`` or ``$fatal`` (``call``: which, and the file
    and line of the call) at edge ``cycle``; the model runs no further edge until the next
    ``reset()``."""

    def __init__(self, call, cycle):
        self.call, self.cycle = call, cycle
        super().__init__(f"the design called {call} (edge {cycle})")


class StopLimit(RuntimeError):
    """``run`` stopped at a watched change more often since the reset than the backend's
    ``stop_limit`` allows: a budget of work counted in the design's own changes, so that
    where it ends does not depend on the machine's speed."""


@dataclass(frozen=True)
class Port:
    name: str
    width: int
    direction: str  # "in" (the design reads it) or "out" (the design drives it)
    signed: bool = False


@dataclass(frozen=True)
class PixelTiming:
    """Where a frame's pixels fall on the clock: see the module docstring."""

    start: int  # absolute edge of pixel (0, 0)
    line_period: int  # edges from one line's first pixel to the next line's
    pixel_period: int = 1  # edges between neighbouring pixels of a line

    def edge_of(self, y, x):
        return self.start + y * self.line_period + x * self.pixel_period

    def last_edge(self, width, height):
        return self.edge_of(height - 1, width - 1)


@dataclass(frozen=True)
class Stop:
    """Why ``run`` returned: ``port`` None when all the cycles asked for were run."""

    cycle: int  # the absolute edge run last
    port: str | None = None
    value: int | None = None


class PinBackend(ABC):
    """A design simulated clock by clock with every port reachable by name."""

    name = "abstract"

    #: name -> Port, every port except the clock and the reset.
    ports: dict

    @property
    @abstractmethod
    def cycle(self):
        """Rising edges since the last reset."""

    @abstractmethod
    def reset(self):
        """Synchronous reset, as after power-on; drops scheduled changes, the pixel stream
        and the watch list; inputs return to 0."""

    @abstractmethod
    def poke(self, name, value):
        """Input ``name`` takes ``value`` from edge ``cycle + 1`` on."""

    @abstractmethod
    def peek(self, name):
        """The settled value of port ``name``."""

    @abstractmethod
    def schedule(self, edge, name, value):
        """Input ``name`` takes ``value`` from edge ``edge`` on (``edge > cycle``)."""

    @abstractmethod
    def watch(self, names):
        """Outputs whose change stops ``run`` (replaces the previous list)."""

    @abstractmethod
    def stream_frame(self, packed, timing):
        """Queue one frame (an (H, W) uint16 array of RGB444 pixels) on the pixel stream."""

    @property
    @abstractmethod
    def frame_pending(self):
        """True while a queued frame still has pixels to present."""

    @abstractmethod
    def filtered_frame(self):
        """The filtered stream of the last frame, (H, W) uint16, or None without one."""

    @abstractmethod
    def run(self, cycles):
        """Run up to ``cycles`` edges; returns a ``Stop``."""

    def close(self):
        """Release resources (compiled models)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
