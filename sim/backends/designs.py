"""The designs the compiled backends can build: ``FollowTarget`` (what every backend
simulates) and ``PassThrough`` (the benchmark's one-pixel-per-clock reference). Both have the
port list of docs/contract.md, so one harness drives either.
"""

import functools

from ...hw.params import FollowTargetParams
from ...hw.top import FollowTarget
from ...hw.verilog import TOP_NAME, generate_cxxrtl, generate_verilog
from .passthrough import PassThrough

__all__ = ["DESIGNS", "TOP_NAME", "DesignSource"]

#: Designs that ``design=`` accepts.
DESIGNS = ("follow_target", "passthrough", "passthrough_comb")


class DesignSource:
    """One design at one parameter set: its latencies and generated sources.

    Parameters
    ----------
    params : FollowTargetParams
    design : str
        ``"follow_target"``, ``"passthrough"`` (the benchmark's trivial design) or
        ``"passthrough_comb"`` (the same with combinational outputs, for tests).
    """

    def __init__(self, params, design="follow_target"):
        if not isinstance(params, FollowTargetParams):
            raise TypeError("params must be a FollowTargetParams")
        if design not in DESIGNS:
            raise ValueError(f"unknown design {design!r}; choose one of: {', '.join(DESIGNS)}")
        self.params = params
        self.design = design
        latencies = params if design == "follow_target" else self._passthrough_class()
        self.filter_latency = latencies.filter_latency
        self.result_latency = latencies.result_latency
        self.motor_latency = latencies.motor_latency

    @staticmethod
    def _passthrough_class():
        return PassThrough

    def component(self):
        if self.design == "follow_target":
            return FollowTarget(self.params)
        return self._passthrough_class()(
            self.params, registered_outputs=self.design == "passthrough"
        )

    def verilog(self):
        """Verilog text, top module ``follow_target``."""
        return _generated(self.params, self.design, "verilog")

    def cxxrtl(self):
        """CXXRTL C++ text (``amaranth.back.cxxrtl``), top class ``p_follow__target``."""
        return _generated(self.params, self.design, "cxxrtl")

    def _verilog(self):
        if self.design == "follow_target":
            return generate_verilog(self.params)
        return generate_verilog(component=self.component())

    def _cxxrtl(self):
        return generate_cxxrtl(self.component())

    def watchdog_edges(self, line_blank, frame_blank):
        """Edges after which a frame without ``frame_done`` counts as hung: the expected
        length plus a generous margin, so a wrong latency shows as a cycle mismatch first."""
        p = self.params
        pixel_edges = p.height * (p.width + line_blank)
        expected = max(
            pixel_edges + frame_blank,
            pixel_edges - line_blank + self.result_latency + self.motor_latency,
        )
        return expected + 4 * (self.result_latency + self.motor_latency) + 4096


@functools.lru_cache(maxsize=16)
def _generated(params, design, language):
    """Generated source text, kept per process: elaboration and Yosys take a second or two,
    and a cached build still needs the source to check its key."""
    source = DesignSource(params, design)
    return source._verilog() if language == "verilog" else source._cxxrtl()
