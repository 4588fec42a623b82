"""Formal checks of the gateware's promises (docs/formal.md): harnesses written in Amaranth
with ``Assert``/``Assume``/``Cover``, and ``CHECKS``, the list that ``python -m
fpga_robotics.formal`` and ``pytest -m formal`` run with SymbiYosys.

Each check is named ``part.promise`` and, where the parameters matter, ``@size``.
"""

from ..board.gopigo3_spi import SPIByteMaster
from ..board.ov7670_capture import OV7670Capture
from ..board.sccb import SCCBInit
from ..color_filter import ColorFilter
from ..motor import MotorController
from ..params import FollowTargetParams
from ..top import FollowTarget
from ..tracker import TrackerResults
from ..window_counter import WindowCounter
from .capture import CaptureHarness
from .color_filter import ColorFilterHarness
from .follow_target import FollowTargetCovers, FrameDoneHarness
from .harness import MODES, FormalCheck, Harness
from .motor import MotorHarness
from .sccb import SCCB_TABLE, SCCBHarness
from .sizes import FULL_SIZES, SMALL
from .spi import SPIHarness
from .tracker import NoLeakMiter, ProximityMonotonic, ResultsFormulas

__all__ = [
    "CHECKS",
    "FILTER_SETS",
    "MODES",
    "MOTOR_ODD",
    "FormalCheck",
    "Harness",
    "check_named",
]

P160, P640 = FULL_SIZES["160x120"], FULL_SIZES["640x480"]

#: Motor parameters far from the defaults: one lost frame searches, a negative gain with a
#: shift, a low limit, a search speed of the limit's size turning the other way.
MOTOR_ODD = FollowTargetParams(lost_frames=1, kp_num=-7, kp_shift=2, max_dps=300, search_dps=-300)

#: Colour thresholds at both ends of their range.
FILTER_SETS = {
    "defaults": P160,
    "zero": P160.replace(diff_min=0, similar_max=0, white_min=0),
    "max": P160.replace(diff_min=15, similar_max=15, white_min=15),
}


def _results_depth(p):
    """Cycles for one frame's counts to come out of ``TrackerResults``, and one more."""
    return p.result_latency - p.filter_latency + 2


def _frame_done(promise, mode, depth, text):
    return FormalCheck(
        f"frame_done.{promise}@16x2",
        mode,
        depth,
        text,
        build=lambda dut=None: FrameDoneHarness(promise, dut),
        make_dut=lambda: FollowTarget(SMALL),
    )


CHECKS = [
    # 1, 2: FollowTarget's frame_done.
    _frame_done("strobe", "prove", 4, "frame_done is never high two cycles in a row"),
    _frame_done(
        "well_formed_only",
        "bmc",
        60,
        "frame_done only result_latency edges after a well-formed frame's last pixel",
    ),
    _frame_done(
        "latency",
        "bmc",
        60,
        "frame_done exactly result_latency edges after every well-formed frame, "
        "whatever came before",
    ),
    # 3: a miter of two trackers.
    FormalCheck(
        "tracker.no_leak@16x2",
        "bmc",
        54,
        "two trackers, one fed 20 cycles of anything first, agree on every count after "
        "a shared first",
        build=lambda dut=None: NoLeakMiter(dut),
        make_dut=lambda: WindowCounter(SMALL),
    ),
    # 4: the motor controller, for ever (k-induction).
    *[
        FormalCheck(
            f"motor.limits_hold_search@{size}",
            "prove",
            2,
            "wheels within +-max_dps; lost frames hold, then search to the last side",
            build=lambda dut=None, p=p: MotorHarness(dut, p),
            make_dut=lambda p=p: MotorController(p),
        )
        for size, p in (("defaults", P160), ("odd", MOTOR_ODD))
    ],
    # 5: per-frame results from free counts.
    *[
        FormalCheck(
            f"results.counts@{size}",
            "bmc",
            _results_depth(p),
            "found, proximity and the LED code are the contract's formulas of N and "
            "the bins, for every count",
            build=lambda dut=None, p=p: ResultsFormulas("counts", dut, p),
            make_dut=lambda p=p: TrackerResults(p),
        )
        for size, p in (("160x120", P160),)
    ],
    *[
        FormalCheck(
            f"results.centroid@{size}",
            "bmc",
            _results_depth(p),
            "centroid_x is SX // N when found, else 0, for every count",
            build=lambda dut=None, p=p: ResultsFormulas("centroid", dut, p),
            make_dut=lambda p=p: TrackerResults(p),
        )
        for size, p in (("16x2", SMALL),)
    ],
    FormalCheck(
        "results.proximity_monotonic@160x120",
        "bmc",
        _results_depth(P160),
        "more pixels never give a lower proximity, nor lose found",
        build=lambda dut=None: ProximityMonotonic(dut, params=P160),
        make_dut=lambda: TrackerResults(P160),
    ),
    # 6: the colour filter, for ever (k-induction).
    *[
        FormalCheck(
            f"color_filter.table@{name}",
            "prove",
            2,
            "filtered = the contract's colour table for every pixel and colour, "
            "flags and order kept",
            build=lambda dut=None, p=p: ColorFilterHarness(dut, p),
            make_dut=lambda p=p: ColorFilter(p),
        )
        for name, p in FILTER_SETS.items()
    ],
    # 7: board parts.
    FormalCheck(
        "spi.mode0_bytes@half_period=1",
        "bmc",
        40,
        "COPI still while SCLK high, SCLK inside CS, bytes sent as queued",
        build=lambda dut=None: SPIHarness(dut, 1),
        make_dut=lambda: SPIByteMaster(half_period=1),
    ),
    FormalCheck(
        "spi.mode0_bytes@half_period=2",
        "bmc",
        60,
        "COPI still while SCLK high, SCLK inside CS, bytes sent as queued",
        build=lambda dut=None: SPIHarness(dut, 2),
        make_dut=lambda: SPIByteMaster(half_period=2),
    ),
    FormalCheck(
        "sccb.start_stop_bits",
        "bmc",
        260,
        "SIOD changes under SIOC high only as START/STOP; each write's 27 bits",
        build=lambda dut=None: SCCBHarness(dut),
        make_dut=lambda: SCCBInit(SCCB_TABLE, quarter_period=1, reset_wait=6, startup_wait=2),
    ),
    *[
        FormalCheck(
            f"capture.no_overflow@fifo_depth={depth}",
            "bmc",
            40,
            "the camera FIFO never overflows at the camera's pixel rate",
            build=lambda dut=None, depth=depth: CaptureHarness(dut, depth),
            make_dut=lambda depth=depth: OV7670Capture(fifo_depth=depth),
        )
        for depth in (4, 16)
    ],
    # Covers: every interesting state is reachable (no vacuous proof).
    FormalCheck(
        "cover.follow_target@16x2",
        "cover",
        45,
        "frames reach proximity 7 and the centroid reaches both window edges",
        build=lambda dut=None: FollowTargetCovers(dut),
        make_dut=lambda: FollowTarget(SMALL),
    ),
    FormalCheck(
        "cover.results@160x120",
        "cover",
        _results_depth(P160),
        "proximity 7, every LED code",
        build=lambda dut=None: ResultsFormulas("counts", dut, P160),
        make_dut=lambda: TrackerResults(P160),
    ),
    FormalCheck(
        "cover.centroid@16x2",
        "cover",
        _results_depth(SMALL),
        "centroid on the window's first and last columns",
        build=lambda dut=None: ResultsFormulas("centroid", dut, SMALL),
        make_dut=lambda: TrackerResults(SMALL),
    ),
    FormalCheck(
        "cover.motor@defaults",
        "cover",
        20,
        "search both ways, both limits",
        build=lambda dut=None: MotorHarness(dut, P160),
        make_dut=lambda: MotorController(P160),
    ),
    FormalCheck(
        "cover.color_filter@defaults",
        "cover",
        3,
        "a match under every color_sel",
        build=lambda dut=None: ColorFilterHarness(dut, P160),
        make_dut=lambda: ColorFilter(P160),
    ),
    FormalCheck(
        "cover.spi@half_period=1",
        "cover",
        40,
        "a byte 0xA5 sent, two bytes in a message, a whole message",
        build=lambda dut=None: SPIHarness(dut, 1),
        make_dut=lambda: SPIByteMaster(half_period=1),
    ),
    FormalCheck(
        "cover.sccb",
        "cover",
        260,
        "the whole table written",
        build=lambda dut=None: SCCBHarness(dut),
        make_dut=lambda: SCCBInit(SCCB_TABLE, quarter_period=1, reset_wait=6, startup_wait=2),
    ),
    FormalCheck(
        "cover.capture@fifo_depth=4",
        "cover",
        30,
        "a pixel with last comes out",
        build=lambda dut=None: CaptureHarness(dut, 4),
        make_dut=lambda: OV7670Capture(fifo_depth=4),
    ),
]


def check_named(name):
    """The check called ``name`` (``KeyError`` if there is none)."""
    for check in CHECKS:
        if check.name == name:
            return check
    raise KeyError(name)
