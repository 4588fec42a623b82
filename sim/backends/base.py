"""The one interface through which host code drives the design, whatever simulates it.

A backend simulates ``FollowTarget`` for given ``FollowTargetParams`` and processes whole
frames: it streams the pixels row-major, one per clock, with optional blanking (``valid`` low)
after every line and after the frame, then keeps clocking until the frame's results are on the
outputs. State (motor controller, lost counter) persists across frames as in hardware;
``reset()`` returns to the power-on state.

Cycle accounting, shared by every backend so that ``cycles`` is comparable bit for bit:
a frame of H lines takes ``H * (W + line_blank)`` input cycles (each line's W pixel cycles are
followed by ``line_blank`` idle cycles). The driver then runs idle cycles until both
``frame_blank`` idle cycles have passed and the motor outputs show the frame's values.
``FrameResult.cycles`` counts every clock edge of the call.
"""

import os
from abc import ABC, abstractmethod
from dataclasses import dataclass, replace

import numpy as np

from ...hw.params import FollowTargetParams
from ...hw.pixel import color_select_value
from ...hw.validate import check_int
from ..camera.frames import FrameError, to_rgb444

__all__ = ["BackendError", "DesignBackend", "FrameResult", "WaveformRequest", "check_out"]


class BackendError(RuntimeError):
    """A backend cannot be built or run (missing tool, failed compile, hung design)."""


@dataclass(frozen=True)
class WaveformRequest:
    """Write a waveform of the frames ``first_frame`` .. ``last_frame`` (inclusive, counted
    from 0 since construction or the last reset) to ``path`` (``.vcd``, or ``.fst`` where the
    backend supports it). Nothing is traced outside that range."""

    path: str
    first_frame: int = 0
    last_frame: int = 0

    def covers(self, frame_index):
        return self.first_frame <= frame_index <= self.last_frame

    def check(self, backend_name, suffixes=(".vcd",), hint=""):
        """Raise ``BackendError`` unless a backend writing ``suffixes`` can honour this request.

        ``hint`` names where to turn for other formats (e.g. "or the verilator backend for
        .fst")."""
        path = os.fspath(self.path)
        if not path.endswith(tuple(suffixes)):
            raise BackendError(
                f"the {backend_name} backend writes {'/'.join(suffixes)} waveforms only, got "
                f"{path!r}; use a {suffixes[0]} path{f' ({hint})' if hint else ''}"
            )
        for name in ("first_frame", "last_frame"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise BackendError(
                    f"the waveform's {name} must be a frame number (a whole number, 0 or "
                    f"more), got {value!r}"
                )
        directory = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(directory):
            raise BackendError(f"cannot write the waveform: no directory {directory!r}")
        if self.last_frame < self.first_frame:
            raise BackendError(
                f"the waveform's last_frame ({self.last_frame}) is before its first_frame "
                f"({self.first_frame})"
            )


@dataclass(frozen=True, eq=False)
class FrameResult:
    """What the design produced for one frame."""

    filtered: np.ndarray  # (H, W) uint16, packed RGB444: the pixel where it matched, else 0
    found: bool
    proximity: int
    centroid_x: int
    centroid_leds: int
    motor_left: int  # signed DPS
    motor_right: int  # signed DPS
    cycles: int
    #: A design of one's own: its outputs no connector reads, by name (None: none).
    extra: dict = None

    def outputs(self):
        """The per-frame scalar outputs as a tuple (for comparisons across backends)."""
        return (
            self.found,
            self.proximity,
            self.centroid_x,
            self.centroid_leds,
            self.motor_left,
            self.motor_right,
            self.cycles,
        )

    def __eq__(self, other):
        if not isinstance(other, FrameResult):
            return NotImplemented
        return self.outputs() == other.outputs() and np.array_equal(self.filtered, other.filtered)


class DesignBackend(ABC):
    """Base of every backend. Subclasses implement ``_reset`` and ``_run_frame``."""

    #: Name used by ``get_backend`` and the CLI.
    name = "abstract"

    def __init__(self, params=None, *, line_blank=0, frame_blank=0, waveform=None):
        self.params = params if params is not None else FollowTargetParams()
        if not isinstance(self.params, FollowTargetParams):
            raise TypeError("params must be a FollowTargetParams")
        check_int("line_blank", line_blank, 0)
        check_int("frame_blank", frame_blank, 0)
        if waveform is not None and not isinstance(waveform, WaveformRequest):
            raise TypeError("waveform must be a WaveformRequest or None")
        self.line_blank = line_blank
        self.frame_blank = frame_blank
        self.waveform = waveform
        self.frames_processed = 0

    def reset(self):
        """Synchronous reset of the whole design, as after power-on."""
        self._reset()
        self.frames_processed = 0

    def watch_risen(self):
        """The bits of the design's watch output (a mutant netlist's ``mutinf``) that rose
        since the last call or reset; None for a backend or design without one."""
        return

    def process_frame(self, frame, color_sel="red", *, out=None):
        """Run one frame through the design and return its ``FrameResult``.

        ``frame`` is RGB888 (H, W, 3) uint8 or packed RGB444 (H, W); ``color_sel`` a colour
        name or its 3-bit code. ``out``, a C-contiguous writable (H, W) uint16 array, receives
        the filtered frame and is the result's ``filtered`` (no new array per frame; the
        next call with the same ``out`` overwrites it). A wrong ``out`` is a ``FrameError``.
        """
        p = self.params
        if out is not None:
            check_out(out, p.width, p.height)
        packed = to_rgb444(frame, p.width, p.height)
        result = self._run_frame(packed, color_select_value(color_sel))
        self.frames_processed += 1
        if out is not None and result.filtered is not None:
            np.copyto(out, result.filtered)
            result = replace(result, filtered=out)
        return result

    def close(self):
        """Release resources (compiled models, trace files)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @abstractmethod
    def _reset(self): ...

    @abstractmethod
    def _run_frame(self, packed, color_sel):
        """Process a validated (H, W) uint16 frame; return a ``FrameResult``."""


def check_out(out, width, height):
    """Raise ``FrameError`` unless ``out`` can receive a ``width`` x ``height`` filtered frame:
    a C-contiguous, writable (height, width) uint16 numpy array."""
    if not isinstance(out, np.ndarray):
        raise FrameError(
            f"out= must be a numpy array, not {type(out).__name__}; make one with "
            f"numpy.empty(({height}, {width}), numpy.uint16)"
        )
    if out.shape != (height, width) or out.dtype != np.uint16:
        raise FrameError(
            f"out= must be a ({height}, {width}) uint16 array for a {width}x{height} "
            f"design, got {out.shape} {out.dtype}; make one with "
            f"numpy.empty(({height}, {width}), numpy.uint16)"
        )
    if not (out.flags.c_contiguous and out.flags.writeable):
        raise FrameError(
            "out= must be a C-contiguous, writable array (not a view with strides "
            "or a read-only array)"
        )
