"""The ``model`` backend: the numpy golden model behind the frame-level backend API.

It needs no toolchain and runs a 160x120 frame in well under a millisecond, so it is the
fallback of the closed loop and the reference every clocked backend is compared with. Its
``cycles`` come from the documented latencies (``FollowTargetParams.result_latency`` and
``motor_latency``) with the shared frame-driver accounting, so a clocked backend that agrees
on ``cycles`` also agrees on the latency. A ``WaveformRequest`` gets a VCD of the ports
reconstructed from the model at cycle level (see ``model_waveform``); it cannot show internal
signals: use the ``pysim``, ``cxxrtl`` or ``verilator`` backend for those.
"""

from ..models.follow_target import FollowTargetModel
from .base import DesignBackend, FrameResult
from .model_waveform import ModelWaveformWriter

__all__ = ["ModelBackend", "frame_cycles"]


def frame_cycles(params, line_blank, frame_blank):
    """Clock edges of one ``process_frame`` call (the shared accounting of base.py).

    ``max(H * (W + line_blank) + frame_blank, P + result_latency + motor_latency)`` with
    ``P = H * (W + line_blank) - line_blank``, the edge that samples the last pixel.
    """
    input_cycles = params.height * (params.width + line_blank)
    last_pixel_edge = input_cycles - line_blank
    return max(
        input_cycles + frame_blank,
        last_pixel_edge + params.result_latency + params.motor_latency,
    )


class ModelBackend(DesignBackend):
    """``FollowTarget`` simulated by the numpy golden model (no clock).

    Parameters
    ----------
    params : FollowTargetParams, optional
    line_blank, frame_blank : int
        Idle cycles after every line / after the frame; they only change ``cycles``.
    waveform : WaveformRequest, optional
        Writes a ``.vcd`` of the ports for the requested frames. The file appears when the
        last requested frame is done, or at ``close()``/``reset()`` with the frames done so far;
        a backend dropped before then leaves no file.
    """

    name = "model"

    def __init__(self, params=None, *, line_blank=0, frame_blank=0, waveform=None):
        super().__init__(params, line_blank=line_blank, frame_blank=frame_blank, waveform=waveform)
        if waveform is not None:
            waveform.check("model", hint="or the verilator backend for .fst")
        self.model = FollowTargetModel(self.params)
        self._cycles = frame_cycles(self.params, line_blank, frame_blank)
        self._tracer = None
        self._traced = False  # the requested waveform has been written
        self._shown = (False, 0, 0, 0, 0, 0)  # outputs on the ports now

    def _reset(self):
        self._finish_trace()
        self.model.reset()
        self._shown = (False, 0, 0, 0, 0, 0)

    def _run_frame(self, packed, color_sel):
        out = self.model.process(packed, color_sel)
        t = out.tracker
        outputs = (
            t.found,
            t.proximity,
            t.centroid_x,
            t.centroid_leds,
            out.motor_left,
            out.motor_right,
        )
        index = self.frames_processed
        if self.waveform is not None and not self._traced and self.waveform.covers(index):
            if self._tracer is None:
                self._tracer = ModelWaveformWriter(
                    self.waveform.path,
                    self.params,
                    line_blank=self.line_blank,
                    outputs=self._shown,
                )
            try:
                self._tracer.add_frame(packed, color_sel, out.filtered, outputs, self._cycles)
            except BaseException:
                self._tracer.abort()
                self._tracer = None
                self._traced = True
                raise
            if index == self.waveform.last_frame:
                self._finish_trace()
        self._shown = outputs
        return FrameResult(
            filtered=out.filtered,
            found=bool(t.found),
            proximity=t.proximity,
            centroid_x=t.centroid_x,
            centroid_leds=t.centroid_leds,
            motor_left=out.motor_left,
            motor_right=out.motor_right,
            cycles=self._cycles,
        )

    def _finish_trace(self):
        if self._tracer is not None:
            tracer, self._tracer = self._tracer, None
            self._traced = True
            tracer.finish()

    def close(self):
        self._finish_trace()
