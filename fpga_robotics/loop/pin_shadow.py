"""Shadow runs in real-clock timing: a second design (``run --shadow REF``) gets, cycle for
cycle, the inputs the primary design gets (the connectors' pins, the camera's stream) without
driving anything; at every trajectory row their wheels (through the ports each binds them
to) and their other outputs of the same names are compared.

This is how a new version of a design of one's own is checked against the previous one in
the closed loop: the robot moves as the primary decides, both see the same world, and the
first row where an output differs is the place to look.
"""

from dataclasses import dataclass, field

from fpga_robotics.designs.builtin import TOPS
from fpga_robotics.designs.reference import entry_point_designs
from fpga_robotics.sim.pins import DesignStopped

__all__ = ["MirroredPins", "PinComparison", "ShadowStopped", "is_design_reference"]


def is_design_reference(spec):
    """Whether ``--shadow SPEC`` names a design (a built-in or installed name, ``FILE.py:Name``,
    ``module:Name``) rather than FollowTarget parameters (a preset, ``KEY=VALUE`` items)."""
    spec = str(spec).strip()
    if "=" in spec or ";" in spec:
        return False
    return ":" in spec or spec in TOPS or spec in entry_point_designs()


class ShadowStopped(DesignStopped):
    """The shadow design (not the primary) called ``$finish``, ``$stop`` or ``$fatal``."""


class MirroredPins:
    """The primary ``PinBackend`` as the loop sees it, every input it is given also given to
    ``shadow``, both at the same edge: to the shadow's input that serves the same connector
    pin (``mirror``; a Verilog design's ports keep their own names), else to its input of
    the same name."""

    def __init__(self, primary, shadow):
        self.primary, self.shadow = primary, shadow
        self._inputs = {n for n, p in shadow.ports.items() if p.direction == "in"}
        self._to_shadow = {n: n for n in self._inputs}  # primary input -> shadow input

    def mirror(self, primary_port, shadow_port):
        """Give the shadow's input ``shadow_port`` what the primary's ``primary_port`` gets
        (both bound to one connector pin); ignored for a port the shadow does not have."""
        if shadow_port in self._inputs:
            self._to_shadow[primary_port] = shadow_port

    @property
    def name(self):
        return self.primary.name

    @property
    def ports(self):
        return self.primary.ports

    @property
    def cycle(self):
        return self.primary.cycle

    @property
    def frame_pending(self):
        return self.primary.frame_pending

    def reset(self):
        self.primary.reset()
        self.shadow.reset()

    def poke(self, name, value):
        self.primary.poke(name, value)
        if name in self._to_shadow:
            self.shadow.poke(self._to_shadow[name], value)

    def schedule(self, edge, name, value):
        self.primary.schedule(edge, name, value)
        if name in self._to_shadow:
            self.shadow.schedule(edge, self._to_shadow[name], value)

    def stream_frame(self, packed, timing):
        self.primary.stream_frame(packed, timing)
        if getattr(self.shadow.source, "pixels", None):  # a camera design, its stream bound
            self.shadow.stream_frame(packed, timing)

    def peek(self, name):
        return self.primary.peek(name)

    def watch(self, names):
        self.primary.watch(names)

    def filtered_frame(self):
        return self.primary.filtered_frame()

    def run(self, cycles):
        stop = self.primary.run(cycles)
        while self.shadow.cycle < self.primary.cycle:  # it watches nothing: one call, usually
            try:
                self.shadow.run(self.primary.cycle - self.shadow.cycle)
            except DesignStopped as exc:  # the shadow's own call, not the primary's
                raise ShadowStopped(exc.call, exc.cycle) from None
        return stop

    def close(self):
        """The backends belong to who opened them: nothing to release here."""


@dataclass
class PinComparison:
    """Where the shadow's outputs differ from the primary's, row by row, over ``outputs``
    (the wheels and the outputs both designs have; the same keys as
    ``loop.shadow.ShadowComparison.summary``)."""

    label: str
    outputs: tuple = ()
    differing_frames: dict = field(default_factory=dict)
    first_divergence: dict | None = None
    frames: int = 0
    params: dict | None = None  # a design of one's own's [design.params]; None: it takes none

    def __post_init__(self):
        self.differing_frames = dict.fromkeys(self.outputs, 0)

    def compare(self, frame, time_s, primary, shadow):
        """Compare one row's outputs (``{name: value}`` each); return the names that differ."""
        self.frames += 1
        differ = [n for n in self.outputs if primary[n] != shadow[n]]
        for name in differ:
            self.differing_frames[name] += 1
        if differ and self.first_divergence is None:
            self.first_divergence = {
                "frame": frame,
                "time_s": round(time_s, 6),
                "outputs": {
                    n: {"primary": int(primary[n]), "shadow": int(shadow[n])} for n in differ
                },
            }
        return differ

    def summary(self):
        params = {} if self.params is None else {"params": dict(self.params)}
        return {
            "design": self.label,
            **params,
            "frames": self.frames,
            "first_divergence": self.first_divergence,
            "differing_frames": dict(self.differing_frames),
        }
