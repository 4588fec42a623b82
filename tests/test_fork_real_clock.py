"""Fork at divergence in real-clock timing: a pin design variant judged against a reference
run gives the same result as its own full run, whether it never parts from the reference,
parts at frame 0, only in the last frame, or in between (restored from a checkpoint)."""

import pickle
from pathlib import Path

import numpy as np
import pytest
from pin_proxy import PinProxy
from run_equality import assert_same_run

from fpga_robotics.loop.pin_fork import PinReferenceRun, reference_run
from fpga_robotics.loop.real_clock import make_pin_backend
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

WALL_STOP = Path(__file__).parent / "data" / "user_designs" / "wall_stop.toml"


class FasterLeftWheel(PinProxy):
    """A pin design whose left wheel pin reads ``extra`` higher from edge ``edge`` on (a
    design that parts from its original there); every other call passes through."""

    def __init__(self, design, edge, extra=120):
        super().__init__(design)
        self.edge, self.extra = edge, extra
        self.name = "faster_left"

    def peek(self, name):
        value = self.inner.peek(name)
        if name == "motor_left" and self.inner.cycle >= self.edge:
            value += self.extra
        return value


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("line_track", ["sim.duration=1.5"])


@pytest.fixture(scope="module")
def reference(scenario):
    with make_pin_backend("cxxrtl", scenario) as design:
        yield reference_run(scenario, design=design, checkpoint_every=7)


def fork_and_full(reference, scenario, variant):
    forked = reference.run_variant(variant, scenario)
    diverged = reference.last_divergence
    assert_same_run(forked, run_scenario(scenario, backend=variant))
    return forked, diverged


def test_the_reference_is_the_plain_run(scenario, reference):
    assert isinstance(reference, PinReferenceRun)
    with make_pin_backend("cxxrtl", scenario) as design:
        assert_same_run(reference.result, run_scenario(scenario, backend=design))


def test_the_same_design_never_parts(scenario, reference):
    with make_pin_backend("cxxrtl", scenario) as variant:
        forked, diverged = fork_and_full(reference, scenario, variant)
    assert diverged is None
    assert_same_run(forked, reference.result)


def test_a_variant_that_parts_at_frame_0(scenario, reference):
    # Its wheel pins out of reset are another command already.
    with make_pin_backend("cxxrtl", scenario) as design:
        forked, diverged = fork_and_full(reference, scenario, FasterLeftWheel(design, 0))
    assert diverged == 0
    assert not np.array_equal(forked.trajectory["heading"], reference.result.trajectory["heading"])


def test_a_parameter_variant_is_its_own_full_run(scenario, reference):
    # The wheels turn only once the design's first command is out: frame 1.
    slower = scenario.with_overrides(["design.line.base_dps=300"])
    with make_pin_backend("cxxrtl", slower) as variant:
        forked = reference.run_variant(variant, slower)
        assert reference.last_divergence == 1
        assert_same_run(forked, run_scenario(slower, backend=variant))
    assert forked.summary["overrides"][-1] == "design.line.base_dps=300"
    assert not np.array_equal(forked.trajectory["x"], reference.result.trajectory["x"])


def _edge_of_frame(reference, scenario, k):
    loop = reference._loop
    return loop.edge_of_step(round(k * loop.period / loop.dt))


def test_a_variant_that_parts_in_the_last_frame(scenario, reference):
    last = reference.frames - 1
    with make_pin_backend("cxxrtl", scenario) as design:
        variant = FasterLeftWheel(design, _edge_of_frame(reference, scenario, last))
        forked, diverged = fork_and_full(reference, scenario, variant)
    assert diverged == last
    ref = reference.result.trajectory
    assert np.array_equal(forked.trajectory["x"], ref["x"])
    assert forked.trajectory["motor_left"][last - 1] == ref["motor_left"][last - 1] + 120


def test_a_variant_that_parts_between_checkpoints(scenario, reference):
    k = 17  # between the checkpoints at frames 14 and 21
    with make_pin_backend("cxxrtl", scenario) as design:
        variant = FasterLeftWheel(design, _edge_of_frame(reference, scenario, k))
        forked, diverged = fork_and_full(reference, scenario, variant)
    assert diverged == k
    ref = reference.result.trajectory
    # Row k - 1's wheels are read at frame k's capture: the left one is faster there, and
    # the robot turns off its reference path from then on (the design answers the turn).
    left = forked.trajectory["motor_left"]
    assert np.array_equal(left[: k - 1], ref["motor_left"][: k - 1])
    assert left[k - 1] == ref["motor_left"][k - 1] + 120
    heading = forked.trajectory["heading"]
    assert np.array_equal(heading[: k + 1], ref["heading"][: k + 1])
    assert not np.array_equal(heading[k + 1 :], ref["heading"][k + 1 :])


def test_the_portable_reference_forks_as_the_reference(scenario, reference):
    # Pickled and opened again (as another worker gets it), without its design: each variant
    # parts where it parts from the original, restored from the same checkpoint, and its run
    # is its full run.
    opened = PinReferenceRun.from_portable(pickle.loads(pickle.dumps(reference.portable())))
    assert opened.frames == reference.frames
    last = reference.frames - 1
    parted = []
    for k in (None, 0, 17, last):
        with make_pin_backend("cxxrtl", scenario) as design:
            edge = None if k is None else _edge_of_frame(reference, scenario, k)
            variant = design if k is None else FasterLeftWheel(design, edge)
            theirs = opened.run_variant(variant, scenario)
            mine = reference.run_variant(variant, scenario)
            assert (opened.last_divergence, opened.last_world_from) == (
                reference.last_divergence,
                reference.last_world_from,
            ), k
            assert_same_run(theirs, mine)
            assert_same_run(theirs, run_scenario(scenario, backend=variant))
            parted.append(opened.last_divergence)
    assert parted == [None, 0, 17, last]


def test_a_variant_world_must_be_the_reference_world(scenario, reference):
    other = scenario.with_overrides(["seed=99"])
    with make_pin_backend("cxxrtl", other) as variant, pytest.raises(ValueError, match="differ"):
        reference.run_variant(variant, other)


@pytest.mark.slow
def test_a_robot_with_a_pan_camera_forks_in_real_clock_timing():
    # The turret robot: the pan camera streams into the design's pins and its servo follows
    # them, so after a restore both must talk to the variant's design, not the reference's.
    turret = load_scenario("turret", ["sim.duration=6", "sim.timing=real_clock"])
    with make_pin_backend("cxxrtl", turret) as design:
        reference = reference_run(turret, design=design)
    # A smaller search step turns the pan camera otherwise once it has lost the target.
    other = turret.with_overrides(["design.turret.search_step=3"])
    with make_pin_backend("cxxrtl", other) as variant:
        forked = reference.run_variant(variant, other)
        diverged = reference.last_divergence
        assert_same_run(forked, run_scenario(other, backend=variant))
    assert diverged is not None and diverged >= 30  # restored from a later checkpoint
    ref = reference.result.trajectory
    assert not np.array_equal(forked.trajectory["turret.servo_angle"], ref["turret.servo_angle"])


class OtherReading(PinProxy):
    """A pin design whose extra output ``port`` reads ``extra`` higher from edge ``edge`` on
    (an output that drives nothing)."""

    def __init__(self, design, port, edge, extra=7):
        super().__init__(design)
        self.port, self.edge, self.extra = port, edge, extra
        self.name = "other_reading"

    def peek(self, name):
        value = self.inner.peek(name)
        if name == self.port and self.inner.cycle >= self.edge:
            value += self.extra
        return value


@pytest.fixture(scope="module")
def wall_stop():
    """A user design with extra outputs (distance_mm, stopped), 3 s, and its reference."""
    s = load_scenario(str(WALL_STOP), ["sim.duration=3"])
    with make_pin_backend("cxxrtl", s) as design:
        yield s, reference_run(s, design=design, checkpoint_every=20)


def test_a_variant_that_differs_only_in_an_extra_output_keeps_the_reference_world(wall_stop):
    scenario, reference = wall_stop
    k = 25
    with make_pin_backend("cxxrtl", scenario) as design:
        variant = OtherReading(design, "distance_mm", _edge_of_frame(reference, scenario, k))
        forked, diverged = fork_and_full(reference, scenario, variant)
    # The distance it reports drives nothing: no frame parts, no world simulated again.
    assert diverged is None and reference.last_world_from is None
    ref = reference.result.trajectory
    ours = forked.trajectory["design.distance_mm"]
    assert np.array_equal(ours[: k - 1], ref["design.distance_mm"][: k - 1])
    assert np.array_equal(ours[k:], ref["design.distance_mm"][k:] + 7)
    assert np.array_equal(forked.trajectory["x"], ref["x"])


def test_a_variant_whose_extra_output_differs_before_it_parts_keeps_both(wall_stop):
    # The extra output differs from frame 5 (before the checkpoint at 20), the wheels from
    # frame 50: the world is simulated again from 40, the rows before it get the variant's
    # extra output, and the result is its full run's.
    scenario, reference = wall_stop
    with make_pin_backend("cxxrtl", scenario) as design:
        variant = FasterLeftWheel(
            OtherReading(design, "distance_mm", _edge_of_frame(reference, scenario, 5)),
            _edge_of_frame(reference, scenario, 50),
        )
        forked, diverged = fork_and_full(reference, scenario, variant)
    assert diverged == 50 and reference.last_world_from == 40
    ref = reference.result.trajectory["design.distance_mm"]
    assert np.array_equal(forked.trajectory["design.distance_mm"][5:40], ref[5:40] + 7)
