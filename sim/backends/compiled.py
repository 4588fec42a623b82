"""Shared Python side of the compiled backends: loading a harness library through ctypes and
running whole frames in it (one call per frame, the frame passed as a pointer).

An RGB888 frame goes to the harness as it is (``fr_run_frame_rgb888``: the C++ loop packs
each pixel to RGB444 as it streams it in), so ``process_frame`` on the host does little more
than the call: check the shape, pick the entry point, read the results.

Subclasses say how to build the library (``_build``) for a ``DesignSource`` and variant:
``"plain"`` (no tracing code at all, the fast one) or ``"vcd"``/``"fst"`` (a separate build
with a waveform writer, made only when a ``WaveformRequest`` asks for it).
"""

import contextlib
import ctypes
from pathlib import Path

import numpy as np

from ...hw.pixel import color_select_value
from ..camera.frames import to_rgb444
from ..files import PendingOutput
from .base import BackendError, DesignBackend, FrameResult, check_out
from .designs import DesignSource
from .lifecycle import BuildPlan, bind_library, load_built

__all__ = [
    "ABI_VERSION",
    "HARNESS_DIR",
    "LIBRARY_NAME",
    "BuildPlan",
    "CompiledBackend",
    "HarnessFrames",
]

#: Directory of the C++ harness sources (package data).
HARNESS_DIR = Path(__file__).resolve().parent
#: File name of the harness library in a cache entry.
LIBRARY_NAME = "libfollow_target.so"
#: Must match ``fr::ABI_VERSION`` in frame_driver.h.
ABI_VERSION = 2

# Layout of the argument and result arrays (enums Arg and Out in frame_driver.h).
_N_ARGS, _N_OUT = 7, 11
_O_LOOP_NS = 10
_STATUS = {
    1: "the design never raised frame_done (watchdog after {cycles} cycles): it hung or "
    "its result latency is far from the documented one",
    2: "the design produced more filtered pixels than the frame has",
    3: "the design produced {filtered} filtered pixels for a frame of {pixels}",
    4: "filtered pixel {bad} carries wrong first/last framing flags",
    5: "the harness rejected the frame arguments",
}

_VP = ctypes.c_void_p


class _Library:
    """A loaded harness library and its C entry points."""

    _ENTRIES = (
        ("fr_abi_version", ctypes.c_int, []),
        ("fr_traced", ctypes.c_int, []),
        ("fr_evals_per_cycle", ctypes.c_int, []),
        ("fr_create", _VP, []),
        ("fr_destroy", None, [_VP]),
        ("fr_reset", None, [_VP]),
        ("fr_trace_open", ctypes.c_int, [_VP, ctypes.c_char_p]),
        ("fr_trace_enable", None, [_VP, ctypes.c_int]),
        ("fr_trace_close", None, [_VP]),
        ("fr_run_frame", ctypes.c_int, [_VP, _VP, _VP, _VP, _VP]),
        ("fr_run_frame_rgb888", ctypes.c_int, [_VP, _VP, _VP, _VP, _VP]),
    )

    def __init__(self, path):
        self.lib = bind_library(
            path, self._ENTRIES, what="compiled model", abi_entry="fr_abi_version", abi=ABI_VERSION
        )
        self.path = path
        #: Simulator evaluations per clock cycle (1 when every output is read from flip-flops).
        self.evals_per_cycle = self.lib.fr_evals_per_cycle()


_U8 = np.dtype(np.uint8)


def _address(array):
    return array.__array_interface__["data"][0]  # faster than array.ctypes.data


class HarnessFrames:
    """``process_frame`` through a harness library (``_Library``) whose results land in the
    int64 array ``self._out``: an RGB888 frame, C-contiguous (H, W, 3) uint8, is passed to
    ``fr_run_frame_rgb888`` unconverted; anything else is checked and packed by ``to_rgb444``
    and passed to ``fr_run_frame``. Subclasses implement ``_run_harness(entry, frame,
    color_sel, filtered)``: one call of ``entry`` and the ``FrameResult``."""

    def _live(self):
        """The model's handle for a call into the harness; ``BackendError`` once ``close()``
        has freed the model (the harness would dereference a null model and crash Python)."""
        if self._handle is None:
            raise BackendError(
                f"{self.name}: the backend is closed; open a new one to run the design again"
            )
        return self._handle

    def _init_harness(self):
        p = self.params
        self._shape = (p.height, p.width)
        self._rgb_shape = (p.height, p.width, 3)
        lib = self._library.lib
        self._entry_rgb888, self._entry_packed = lib.fr_run_frame_rgb888, lib.fr_run_frame
        self._out_address = _address(self._out)
        self._args_address = _address(self._args)

    def process_frame(self, frame, color_sel="red", *, out=None):
        # The common case first, in as few steps as possible: this runs once per frame.
        code = (
            color_sel
            if type(color_sel) is int and 0 <= color_sel <= 7
            else color_select_value(color_sel)
        )
        if out is None:
            filtered = np.empty(self._shape, np.uint16)
        else:
            check_out(out, self._shape[1], self._shape[0])
            filtered = out
        if (
            type(frame) is np.ndarray
            and frame.dtype is _U8
            and frame.shape == self._rgb_shape
            and frame.flags.c_contiguous
        ):
            result = self._run_harness(self._entry_rgb888, frame, code, filtered)
        else:
            packed = to_rgb444(frame, self._shape[1], self._shape[0])
            result = self._run_harness(self._entry_packed, packed, code, filtered)
        self.frames_processed += 1
        return result

    def _run_frame(self, packed, color_sel):
        return self._run_harness(
            self._entry_packed, packed, color_sel, np.empty(self._shape, np.uint16)
        )

    @property
    def last_loop_seconds(self):
        """Time of the last frame's C++ loop alone (measured in the harness), seconds."""
        return int(self._out[_O_LOOP_NS]) * 1e-9


class CompiledBackend(HarnessFrames, DesignBackend):
    """A backend whose clock loop runs in a compiled C++ harness.

    Parameters
    ----------
    params : FollowTargetParams, optional
    line_blank, frame_blank : int
        Idle cycles after every line and after the frame (see ``DesignBackend``).
    waveform : WaveformRequest, optional
        Trace these frames into a VCD (or FST where supported); uses a separate traced build.
    design : str
        ``"follow_target"`` (default) or ``"passthrough"`` (the benchmark's reference design).
    """

    #: Waveform formats (file suffixes) this flow can write.
    waveform_formats = (".vcd",)

    def __init__(
        self,
        params=None,
        *,
        line_blank=0,
        frame_blank=0,
        waveform=None,
        design="follow_target",
        on_build=None,
    ):
        super().__init__(params, line_blank=line_blank, frame_blank=frame_blank, waveform=waveform)
        # Told (with a one-line text) before a build that is not in the cache: the first run
        # spends seconds compiling, and the user should know why nothing moves.
        self._on_build = on_build
        self.source = DesignSource(self.params, design)
        variant = "plain"
        if waveform is not None:
            others = (
                "or the verilator backend for .fst" if ".fst" not in self.waveform_formats else ""
            )
            waveform.check(self.name, self.waveform_formats, others)
            variant = Path(waveform.path).suffix.lower()[1:]
        self.variant = variant
        self._handle = None
        self._trace_state = "idle"  # idle -> open -> done
        self._trace_tmp = None
        self._library = self._load(variant)
        self._handle = self._library.lib.fr_create()
        if not self._handle:
            raise BackendError(f"the {self.name} model could not be created")
        p = self.params
        self._out = np.zeros(_N_OUT, np.int64)
        self._args = np.array(
            [
                p.width,
                p.height,
                0,
                line_blank,
                frame_blank,
                self.source.motor_latency,
                self.source.watchdog_edges(line_blank, frame_blank),
            ],
            np.int64,
        )
        assert len(self._args) == _N_ARGS
        self._init_harness()

    # Building ----------------------------------------------------------------------------------

    def _load(self, variant):
        """Build (or find in the cache) and load the library (``lifecycle.load_built``)."""
        #: The cache entry in use (``built`` tells whether this construction built it).
        self.cache_entry, library = load_built(
            self.build_plan(self.source, variant),
            LIBRARY_NAME,
            _Library,
            on_build=self._build_notice,
        )
        return library

    def _build_notice(self):
        if self._on_build is not None:
            p = self.params
            self._on_build(
                f"compiling the {self.name} model of {self.source.design} at "
                f"{p.width}x{p.height} (once; later runs load it from the cache)"
            )

    @staticmethod
    def build_plan(source, variant):
        """``BuildPlan`` of the library ``LIBRARY_NAME`` for a ``DesignSource`` and variant."""
        raise NotImplementedError

    # Running -----------------------------------------------------------------------------------

    @property
    def evals_per_cycle(self):
        """Simulator evaluations per clock cycle: 1 when every output is read from
        flip-flops, else 2 (docs/backends.md)."""
        return self._library.evals_per_cycle

    def _reset(self):
        self._library.lib.fr_reset(self._live())

    def _run_harness(self, entry, frame, color_sel, filtered):
        index = self.frames_processed
        if self.waveform is not None:
            tracing = self.waveform.covers(index)
            if tracing and self._trace_state == "idle":
                self._open_trace()
            if self._trace_state == "open":
                self._library.lib.fr_trace_enable(self._live(), int(tracing))
        self._args[2] = color_sel
        status = entry(
            self._live(), _address(frame), self._args_address, _address(filtered), self._out_address
        )
        if self.waveform is not None and tracing and index >= self.waveform.last_frame:
            self._finish_trace()
        cycles, found, proximity, centroid_x, leds, left, right, n_filtered, _, bad, _ = (
            self._out.tolist()
        )
        if status != 0:
            message = _STATUS.get(status, f"harness status {status}").format(
                cycles=cycles, filtered=n_filtered, pixels=filtered.size, bad=bad
            )
            raise BackendError(f"{self.name}: frame {index}: {message}")
        return FrameResult(filtered, bool(found), proximity, centroid_x, leds, left, right, cycles)

    # Waveforms ---------------------------------------------------------------------------------

    def _open_trace(self):
        # Written under a temporary name and renamed when complete.
        self._trace_tmp = PendingOutput(self.waveform.path, what="waveform")
        if self._library.lib.fr_trace_open(self._live(), str(self._trace_tmp.tmp).encode()) != 0:
            self._trace_tmp.discard()
            raise BackendError(f"cannot write the waveform {self.waveform.path}")
        self._trace_state = "open"

    def _finish_trace(self):
        if self._trace_state != "open":
            return
        self._library.lib.fr_trace_close(self._live())
        self._trace_tmp.commit()
        self._trace_state = "done"

    def close(self):
        """Write out a waveform still being traced and free the model."""
        if self._handle is not None:
            if self._trace_state == "open":
                self._finish_trace()
            self._library.lib.fr_destroy(self._handle)
            self._handle = None

    def __del__(self):
        # Interpreter shutdown may have torn down ctypes or os already: nothing to save then.
        with contextlib.suppress(AttributeError, TypeError, OSError, BackendError):
            # Dropped without close() before its last requested frame: the waveform lacks
            # frames, and goes (close() writes out the frames done).
            if getattr(self, "_trace_state", None) == "open":
                self._library.lib.fr_trace_close(self._live())
                self._trace_tmp.discard()
                self._trace_state = "done"
            self.close()
