"""A further camera's design channel on a clocked backend in compressed timing.

``Top.frame_channels`` names a frame-level model for each further pixel bundle of a design
(``turret_pixels`` of TurretTracker: ``sim/models/turret.py``). With ``--backend pysim``,
``cxxrtl`` or ``verilator`` the compressed loop runs that bundle on the design itself instead:
an instance of the whole design on the pin-level backend of that name (sim/pins), its body
camera's bundle idle, each capture streamed one pixel a clock with the frame backends'
blanking, then clocked until the channel's done pulse and one edge more (the registered
outputs show the frame's update then). The channels of a design share nothing but the clock
(TurretTracker's docstring), so the idle body bundle changes none of the channel's outputs,
and the model matches them bit for bit (tests/test_turret_backends.py).
"""

import hashlib
import re

import numpy as np

from fpga_robotics.designs.builtin import build_component
from fpga_robotics.sim.camera.frames import to_rgb444
from fpga_robotics.sim.pins import PinDesignSource, PixelTiming, get_pin_backend, kept_source

__all__ = ["PIN_CHANNEL_BACKENDS", "PinFrameChannel"]

#: The backends a channel runs on as the design (the model backend keeps the channel's model).
PIN_CHANNEL_BACKENDS = ("pysim", "cxxrtl", "verilator")
#: Idle edges after each line, as the frame backends' default harness blanking.
LINE_BLANK = 2
#: Edges the channel may take after its frame's last pixel before it counts as hung.
WATCHDOG = 4096


class PinFrameChannel:
    """The channel ``model`` (a frame channel: ``frame_size``, ``color_port``,
    ``view_ports``, ``done_port``, ``output_ports``) run on the design ``top`` on the pin
    backend ``backend``, its pixels on bundle ``port``."""

    def __init__(self, model, scenario, top, port, backend, *, on_build=None):
        self.frame_size = model.frame_size
        self.color_port, self.view_ports = model.color_port, model.view_ports
        self.done_port, self.output_ports = model.done_port, model.output_ports
        self.port, self.backend = port, backend
        params, tables = scenario.params, scenario.design_tables
        described = f"{top.name}:{port}:{params!r}:{sorted(tables.items())!r}"
        name = re.sub(r"[^A-Za-z0-9_]", "_", top.name)[:32]
        key = f"{name}-{port}-{hashlib.sha256(described.encode()).hexdigest()[:16]}"
        source = kept_source(
            key,
            top,
            lambda: PinDesignSource(
                lambda: build_component(top, params, tables),
                key,
                pixels=(f"{port}__valid", f"{port}__payload"),
                frame_size=self.frame_size,
            ),
        )
        kwargs = {"on_build": on_build} if on_build is not None else {}
        self.pins = get_pin_backend(backend, source, **kwargs)

    def reset(self):
        self.pins.reset()

    def process(self, frame, color_sel):
        """One frame through the design's bundle; the channel's outputs ``{port: value}``."""
        width, height = self.frame_size
        pins = self.pins
        pins.poke(self.color_port, color_sel)
        packed = to_rgb444(frame, width, height).astype(np.uint16)
        start = pins.cycle + 1
        timing = PixelTiming(start=start, line_period=width + LINE_BLANK)
        pins.stream_frame(packed, timing)
        pins.watch([self.done_port])
        last = timing.last_edge(width, height)
        while True:
            stop = pins.run(last + WATCHDOG - pins.cycle)
            if stop.port is None:
                raise RuntimeError(
                    f"the design's {self.done_port} did not rise within {WATCHDOG} clocks "
                    "of the frame's last pixel"
                )
            if stop.value:
                break
        pins.watch([])
        pins.run(1)  # the registered outputs show the frame's update one edge later
        return {name: int(pins.peek(name)) for name in self.output_ports}

    def close(self):
        self.pins.close()

    def __deepcopy__(self, memo):
        # A loop checkpoint (fpga_robotics.loop.checkpoint) copies the rig; a simulator's
        # state is not a Python object it can copy.
        raise TypeError(
            f"a design channel running on {self.backend} cannot be checkpointed; "
            "run the loop on the model backend"
        )
