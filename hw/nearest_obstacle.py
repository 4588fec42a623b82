"""``NearestObstacle``: the nearest return of each LIDAR revolution and its bearing."""

from amaranth import Cat, Module, Signal
from amaranth.lib import data, stream, wiring
from amaranth.lib.wiring import In, Out

from .lidar_params import NearestParams
from .lidar_sample import SAMPLE_FIELDS
from .validate import CheckedArguments

__all__ = ["NEAREST_MM_BITS", "NearestObstacle", "SampleLayout", "sample_stream"]

#: One sample, the fields of the RPLIDAR's packet (``hw/lidar_sample.py``).
SampleLayout = data.StructLayout(SAMPLE_FIELDS)
#: ``nearest_mm`` holds ``distance_q2 >> 2``: up to 16383 mm.
NEAREST_MM_BITS = SAMPLE_FIELDS["distance_q2"] - 2


def sample_stream():
    """The samples' stream: no ready (a sensor does not wait)."""
    return stream.Signature(SampleLayout, always_ready=True)


class NearestObstacle(CheckedArguments, wiring.Component):
    """The nearest counted sample of each revolution (Verilog module ``nearest_obstacle``).

    A sample counts when it is a valid return (``distance_q2 > 0``) of quality at least
    ``min_quality`` and at least ``min_mm`` away. While a revolution runs, a register holds
    its nearest counted sample so far (the first of equal ones). A sample with ``start`` set
    ends the revolution before it: after that edge ``found``, ``nearest_mm``
    (``distance_q2 >> 2``) and ``bearing_q6`` (its angle, 1/64 degree clockwise) show the
    ended revolution's nearest (``found`` 0: none counted; the other two then keep their
    values) and ``updated`` is high for that one cycle; the start sample begins the next
    revolution. All outputs are 0 after reset.

    Members
    -------
    samples : ``In(stream.Signature(SampleLayout, always_ready=True))``
    nearest_mm : ``Out(14)``
    bearing_q6 : ``Out(15)``
    found, updated : ``Out(1)``
    """

    @staticmethod
    def check_arguments(params=None):
        if params is not None and not isinstance(params, NearestParams):
            raise TypeError(f"params must be a NearestParams, not {params!r}")

    def __init__(self, params=None):
        self.params = NearestParams() if params is None else params
        super().__init__(
            {
                "samples": In(sample_stream()),
                "nearest_mm": Out(NEAREST_MM_BITS),
                "bearing_q6": Out(SAMPLE_FIELDS["angle_q6"]),
                "found": Out(1),
                "updated": Out(1),
            }
        )

    def elaborate(self, platform):
        m = Module()
        p = self.params
        s = self.samples.payload
        run = Signal(SampleLayout)  # the revolution's nearest counted sample so far
        run_found = Signal()
        counts = Signal()
        terms = [s.distance_q2 != 0]
        # Bounds of 0 pass everything: left out (a constant comparison is a lint warning).
        if p.min_quality:
            terms.append(s.quality >= p.min_quality)
        if p.min_mm:
            terms.append(s.distance_q2 >= p.min_mm * 4)
        m.d.comb += counts.eq(Cat(*terms).all())
        m.d.sync += self.updated.eq(0)
        with m.If(self.samples.valid):
            with m.If(s.start):
                m.d.sync += [self.found.eq(run_found), self.updated.eq(1), run_found.eq(counts)]
                with m.If(run_found):
                    m.d.sync += [
                        self.nearest_mm.eq(run.distance_q2 >> 2),
                        self.bearing_q6.eq(run.angle_q6),
                    ]
                with m.If(counts):
                    m.d.sync += run.eq(s)
            with m.Elif(counts & (~run_found | (s.distance_q2 < run.distance_q2))):
                m.d.sync += [run.eq(s), run_found.eq(1)]
        return m
