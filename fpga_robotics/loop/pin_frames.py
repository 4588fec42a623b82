"""A camera-only design of one's own in compressed timing: frame by frame on its pin backend.

A design of one's own that binds no connector but the camera and the wheels and raises
``frame_done`` once a frame (``DesignSpec.real_clock_reason``) runs in compressed timing on
the pin backend real-clock timing would run it on (the same build), clocked for its frames
only: each frame streamed one pixel a clock from the next edge on, then clocked until
``frame_done`` rises, when the per-frame outputs (``found``, ``proximity``, ``centroid_x``,
``centroid_leds``) are read, as real-clock timing reads them; then ``SETTLE_EDGES`` edges
more, after which the wheels and the extra outputs are read (in real-clock timing: at the next
capture). The design is not clocked between frames, so its outputs are those of real-clock
timing for a design that only acts on its frames and settles within those edges.
"""

import numpy as np

from fpga_robotics.designs.reference import FRAME_OUTPUTS
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.loop.bindings import scenario_top
from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.sim.backends.base import DesignBackend, FrameResult
from fpga_robotics.sim.pins import DesignError, PixelTiming

__all__ = ["SETTLE_EDGES", "PinFrames", "check_frame_backend", "open_pin_frames"]

#: Edges run after ``frame_done`` rises before the wheels and the extra outputs are read:
#: 20 us at 50 MHz, far less than a camera's blanking between two frames.
SETTLE_EDGES = 1024
_FRAME_STROBE = "frame_done"


def check_frame_backend(name, scenario):
    """``UsageError`` unless the backend ``name`` can run the scenario's design of one's own:
    the model backend is FollowTarget's model."""
    if name == "model":
        raise UsageError(
            f"the model backend is FollowTarget's golden model; design.top = "
            f"{scenario.top!r} runs on --backend auto, cxxrtl, verilator or pysim"
        )


def open_pin_frames(name, scenario, *, on_build=None):
    """The scenario's design of one's own as a frame backend (``PinFrames``) on the pin
    backend ``name`` ("auto": the fastest compiled one)."""
    check_frame_backend(name, scenario)
    return PinFrames(scenario, make_pin_backend(name, scenario, on_build=on_build))


class PinFrames(DesignBackend):
    """``process_frame`` of the scenario's camera-only design on ``pins`` (a ``PinBackend``
    of it, which this backend closes). A frame whose ``frame_done`` does not rise within
    one frame period of the design clock (``sim.clock_hz / camera.fps`` edges) after its
    last pixel is a ``DesignError``."""

    def __init__(self, scenario, pins):
        super().__init__(scenario.params)
        self.pins = pins
        self.name = pins.name
        top = scenario_top(scenario)
        self.label = top.name
        self.top, self.design_params = scenario.top, dict(scenario.design_params)
        self.color_port = top.bindings["camera"].get("color_sel")
        self.frame_outputs = [n for n in FRAME_OUTPUTS if n in pins.ports]
        self.wheels = top.bindings.get("wheels", {})
        self.extra_outputs = dict(top.extra_outputs)
        self.watchdog = round(scenario.sim.clock_hz / scenario.camera.fps)

    def _reset(self):
        self.pins.reset()

    def _run_frame(self, packed, color_sel):
        p, pins = self.params, self.pins
        if self.color_port is not None:
            pins.poke(self.color_port, color_sel)
        start = pins.cycle
        timing = PixelTiming(start=start + 1, line_period=p.width)
        pins.stream_frame(packed, timing)
        pins.watch([_FRAME_STROBE])
        last_pixel = timing.last_edge(p.width, p.height)
        deadline = last_pixel + self.watchdog
        while True:
            stop = pins.run(deadline - pins.cycle)
            if stop.port is None:
                raise DesignError(
                    f"{self.label}: frame {self.frames_processed}: frame_done did not rise "
                    f"within {self.watchdog:,} edges (a frame period at sim.clock_hz) after "
                    f"the frame's last pixel (a {p.width}x{p.height} frame, "
                    f"camera.resolution); compressed timing reads a frame's results when it "
                    f'rises: raise it once a frame, or set sim.timing = "real_clock"'
                )
            if stop.value and stop.cycle < last_pixel:
                # Read now, the results would be the last frame's, and the next frame would
                # start while this one streams (a "last" flag rise ends every line).
                raise DesignError(
                    f"{self.label}: frame {self.frames_processed}: frame_done rose at edge "
                    f"{stop.cycle - start:,}, before the frame's last pixel (edge "
                    f"{last_pixel - start:,}); compressed timing reads a frame's results when "
                    f"it rises: raise it once a frame, after the last pixel of line "
                    f"{p.height - 1} (the stream's last flag ends every line), or set "
                    f'sim.timing = "real_clock"'
                )
            if stop.value:
                break
        outputs = {name: pins.peek(name) for name in self.frame_outputs}
        filtered = pins.filtered_frame()
        pins.watch([])
        pins.run(SETTLE_EDGES)
        for pin in ("motor_left", "motor_right"):
            port = self.wheels.get(pin)
            outputs[pin] = None if port is None else pins.peek(port)
        found = outputs.get("found")
        return FrameResult(
            filtered=None if filtered is None else np.array(filtered, np.uint16),
            found=None if found is None else bool(found),
            proximity=outputs.get("proximity"),
            centroid_x=outputs.get("centroid_x"),
            centroid_leds=outputs.get("centroid_leds"),
            motor_left=outputs["motor_left"],
            motor_right=outputs["motor_right"],
            cycles=pins.cycle - start,
            extra={name: pins.peek(port) for name, port in self.extra_outputs.items()},
        )

    def close(self):
        self.pins.close()
