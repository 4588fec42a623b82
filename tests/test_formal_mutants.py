"""The formal checks bite: for each promise, a copy of the design with one seeded bug (built
here, never in the product; see ``mutants.py``) makes its check fail, and a failing
assertion comes with a counterexample waveform.

Each bug is one a designer could make: a strobe that does not drop, a line length that is not
checked, blanking counted as pixels, a count not cleared at a ``first``, a clamp with one side
missing, a divider comparison off by one, a colour rule with a term left out, a byte one bit
short, a FIFO that is never read."""

import pytest
from mutants import mutant

from fpga_robotics.flow.formal import run_check
from fpga_robotics.hw.board.gopigo3_spi import SPIByteMaster
from fpga_robotics.hw.board.ov7670_capture import OV7670Capture
from fpga_robotics.hw.board.sccb import SCCBInit
from fpga_robotics.hw.color_filter import ColorFilter
from fpga_robotics.hw.divider import SequentialDivider
from fpga_robotics.hw.formal import FILTER_SETS, MOTOR_ODD, check_named
from fpga_robotics.hw.formal.sccb import SCCB_TABLE
from fpga_robotics.hw.formal.sizes import FULL_SIZES, SMALL
from fpga_robotics.hw.motor import MotorController
from fpga_robotics.hw.top import FollowTarget
from fpga_robotics.hw.tracker import FrameTracker, TrackerResults
from fpga_robotics.hw.window_counter import WindowCounter

pytestmark = pytest.mark.formal

P160 = FULL_SIZES["160x120"]


def top_with_tracker(tracker_cls):
    """``FollowTarget`` at the small size whose tracker is ``tracker_cls``."""
    top = mutant(
        FollowTarget,
        "FrameTracker(params, inspect=False)",
        "MutantTracker(params, inspect=False)",
        MutantTracker=tracker_cls,
    )
    return top(SMALL)


def top_with_counter(old, new):
    """``FollowTarget`` whose window counter has ``old`` replaced by ``new``."""
    counter = mutant(WindowCounter, old, new)
    tracker = mutant(
        FrameTracker,
        "self.counter = WindowCounter(params)",
        "self.counter = MutantCounter(params)",
        MutantCounter=counter,
    )
    return top_with_tracker(tracker)


def results_with(old, new, params=P160):
    return mutant(TrackerResults, old, new)(params)


#: check name -> (the bug, a function building the design with it).
BUGS = {
    "frame_done.strobe@16x2": (
        "frame_done is never cleared",
        lambda: top_with_tracker(
            mutant(FrameTracker, "m.d.sync += load(outputs, frame_done=0)", "pass")
        ),
    ),
    "frame_done.well_formed_only@16x2": (
        "the window counter trusts the flags: line lengths are not checked",
        lambda: top_with_counter("shape_ok.eq((px == W - 1) == last)", "shape_ok.eq(1)"),
    ),
    "frame_done.latency@16x2": (
        "blanking cycles are counted as pixels",
        lambda: top_with_counter(
            "in_frame.eq(valid & (first | active))", "in_frame.eq(first | active)"
        ),
    ),
    "tracker.no_leak@16x2": (
        "a first clears the bins but not SX",
        lambda: mutant(
            WindowCounter,
            "bins.eq(0),\n                sx.eq(0),",
            "bins.eq(0),",
        )(SMALL),
    ),
    "motor.limits_hold_search@defaults": (
        "the search starts one lost frame early",
        lambda: mutant(
            MotorController,
            "state.count >= p.lost_frames - 1 if p.lost_frames > 1",
            "state.count >= p.lost_frames - 2 if p.lost_frames > 2",
        )(P160),
    ),
    "motor.limits_hold_search@odd": (
        "the clamp has no lower side",
        lambda: mutant(
            MotorController,
            "return Mux(v > lim, lim, Mux(v < -lim, -lim, v))",
            "return Mux(v > lim, lim, v)",
        )(MOTOR_ODD),
    ),
    "results.counts@160x120": (
        "found is N > min_pixels",
        lambda: results_with(
            "return frame_count() >= p.min_pixels", "return frame_count() > p.min_pixels"
        ),
    ),
    "results.centroid@16x2": (
        "the divider subtracts only when the trial is above the divisor",
        lambda: mutant(
            TrackerResults,
            "m.submodules.divider = div = SequentialDivider(",
            "m.submodules.divider = div = MutantDivider(",
            MutantDivider=mutant(
                SequentialDivider, "fits = trial >= divisor", "fits = trial > divisor"
            ),
        )(SMALL),
    ),
    "results.proximity_monotonic@160x120": (
        "proximity compares N cut to 8 bits",
        lambda: results_with(
            "(frame_count() >= t if t > 0 else Const(1, 1))",
            "(frame_count()[:8] >= t if t > 0 else Const(1, 1))",
        ),
    ),
    "color_filter.table@defaults": (
        "yellow does not ask for r and g to be similar",
        lambda: mutant(
            ColorFilter,
            "TargetColor.YELLOW: similar(r, g) & dominates(r, b)",
            "TargetColor.YELLOW: dominates(r, b)",
        )(P160),
    ),
    "color_filter.table@zero": (
        "the filter drops the last flag",
        lambda: mutant(ColorFilter, "Const(0b11, 2)", "Const(0b01, 2)")(FILTER_SETS["zero"]),
    ),
    "color_filter.table@max": (
        "white compares channels with > instead of >=",
        lambda: mutant(
            ColorFilter,
            "return ~(a - (c + k))[-1] if k >= 0",
            "return ~(a - (c + k + 1))[-1] if k >= 0",
        )(FILTER_SETS["max"]),
    ),
    "spi.mode0_bytes@half_period=1": (
        "a byte is seven bits",
        lambda: mutant(SPIByteMaster, "with m.If(bit != 7):", "with m.If(bit != 6):")(
            half_period=1
        ),
    ),
    "spi.mode0_bytes@half_period=2": (
        "data shifts on the rising edge of SCLK",
        lambda: mutant(
            SPIByteMaster,
            "m.d.sync += [self.sclk.eq(1), timer.eq(",
            "m.d.sync += [self.sclk.eq(1), shift.eq(shift << 1), timer.eq(",
        )(half_period=2),
    ),
    "sccb.start_stop_bits": (
        "SIOD changes while SIOC is high",
        lambda: mutant(
            SCCBInit,
            "m.d.sync += [self.siod_o.eq(current), self.siod_oe",
            "m.d.sync += [self.sioc.eq(1), self.siod_o.eq(current), self.siod_oe",
        )(SCCB_TABLE, quarter_period=1, reset_wait=6, startup_wait=2),
    ),
    "capture.no_overflow@fifo_depth=4": (
        "the FIFO is never read",
        lambda: mutant(OV7670Capture, "fifo.r_en.eq(1),", "fifo.r_en.eq(0),")(fifo_depth=4),
    ),
    "cover.results@160x120": (
        "proximity stops at 6",
        lambda: results_with(
            "for t in p.proximity_thresholds\n",
            "for t in p.proximity_thresholds[:6]\n",
        ),
    ),
}


def test_every_promise_has_a_bug():
    """Each check but the covers (one cover bug shows that the covers bite too) and the
    second capture depth has a seeded bug."""
    from fpga_robotics.hw.formal import CHECKS

    uncovered = {c.name for c in CHECKS if not c.name.startswith("cover.")} - set(BUGS)
    assert uncovered == {"capture.no_overflow@fifo_depth=16"}


#: Depths for checks whose own depth is too short for the bug to show: an induction of 4
#: cycles proves the strobe, but the first frame_done comes 41 cycles after reset, so the
#: counterexample needs a base case that long; the early search shows after 14 lost frames.
BUG_DEPTHS = {"frame_done.strobe@16x2": 45, "motor.limits_hold_search@defaults": 17}


@pytest.mark.parametrize("name", list(BUGS), ids=list(BUGS))
def test_seeded_bug_fails(name, tmp_path):
    check = check_named(name)
    bug, build = BUGS[name]
    result = run_check(check, depth=BUG_DEPTHS.get(name), dut=build(), trace_dir=tmp_path)
    assert result.status == "FAIL", f"{name} with the bug {bug!r}: {result.status}"
    assert result.detail, "the failure should say which statement failed, and where"
    if check.mode == "cover":
        assert "unreached cover" in result.detail
    else:
        assert "failed assertion" in result.detail
        assert result.trace is not None and result.trace.parent == tmp_path
        assert "$enddefinitions" in result.trace.read_text()
