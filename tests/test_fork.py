"""Fork at divergence: a variant design judged against a reference run gives the same
result as its own full run, whether it never drives differently, differs from the first
frame, only in the last one, or somewhere in between."""

import dataclasses

import numpy as np
import pytest
from run_equality import assert_same_run

from fpga_robotics.loop.fork import ReferenceRun
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend


class Altered:
    """The model design with its outputs changed at some frames (``change(k, result)``)."""

    name = "altered"

    def __init__(self, params, change):
        self.inner = ModelBackend(params)
        self.params = params
        self.change = change
        self.k = 0

    def reset(self):
        self.inner.reset()
        self.k = 0

    def process_frame(self, rgb, color_sel):
        result = self.change(self.k, self.inner.process_frame(rgb, color_sel))
        self.k += 1
        return result

    def close(self):
        self.inner.close()


@pytest.fixture(scope="module")
def scenario():
    # Camera noise and a target that walks out of view: every stream and event kind at work.
    return load_scenario("lost_target", ["sim.duration=3", "camera.noise_std=4"])


@pytest.fixture(scope="module")
def reference(scenario):
    with ModelBackend(scenario.params) as design:
        yield ReferenceRun(scenario, design=design, checkpoint_every=7)


def fork_and_full(reference, scenario, variant):
    forked = reference.run_variant(variant)
    diverged = reference.last_divergence
    full = run_scenario(scenario, backend=variant)
    assert_same_run(forked, full)
    return forked, diverged


def test_the_reference_is_the_plain_run(scenario, reference):
    assert_same_run(reference.result, run_scenario(scenario, backend="model"))


def test_a_variant_that_never_drives_differently(scenario, reference):
    # Found never reported: no found/lost events, other metrics, same wheels.
    variant = Altered(
        scenario.params, lambda k, r: dataclasses.replace(r, found=False, proximity=0)
    )
    forked, diverged = fork_and_full(reference, scenario, variant)
    assert diverged is None
    assert forked.trajectory["found"].sum() == 0 < reference.result.trajectory["found"].sum()
    assert np.array_equal(forked.trajectory["x"], reference.result.trajectory["x"])
    assert forked.summary["found_fraction"] != reference.result.summary["found_fraction"]


def _left_plus(frame):
    """Left wheel 90 DPS faster from ``frame`` on."""
    return lambda k, r: dataclasses.replace(r, motor_left=r.motor_left + 90) if k >= frame else r


def test_a_variant_that_differs_from_the_first_frame(scenario, reference):
    forked, diverged = fork_and_full(reference, scenario, Altered(scenario.params, _left_plus(0)))
    assert diverged == 0
    assert not np.array_equal(forked.trajectory["heading"], reference.result.trajectory["heading"])


def test_a_variant_that_differs_in_the_last_frame(scenario, reference):
    last = reference.frames - 1
    variant = Altered(scenario.params, _left_plus(last))
    forked, diverged = fork_and_full(reference, scenario, variant)
    assert diverged == last
    assert forked.trajectory["motor_left"][last] == (
        reference.result.trajectory["motor_left"][last] + 90
    )


def test_a_parameter_variant_is_its_own_full_run(scenario, reference):
    # A lower colour threshold: the noisy image gives another centroid from the first frame.
    variant_scenario = scenario.with_overrides(["design.diff_min=9"])
    with ModelBackend(variant_scenario.params) as variant:
        forked = reference.run_variant(variant, variant_scenario)
        full = run_scenario(variant_scenario, backend=variant)
    assert_same_run(forked, full)
    assert forked.summary["overrides"] == [
        "sim.duration=3",
        "camera.noise_std=4",
        "design.diff_min=9",
    ]


def test_a_variant_that_parts_between_checkpoints():
    # Searching after 5 lost frames instead of 15, the other way: the designs part when the
    # target has been out of view for 5 frames, well after the run's start, and the world is
    # restored from the checkpoint before that frame.
    s = load_scenario("lost_target", ["sim.duration=6", "camera.noise_std=4"])
    variant_scenario = s.with_overrides(["design.lost_frames=5", "design.search_dps=-300"])
    with ModelBackend(s.params) as design, ModelBackend(variant_scenario.params) as variant:
        reference = ReferenceRun(s, design=design, checkpoint_every=10)
        forked = reference.run_variant(variant, variant_scenario)
        diverged = reference.last_divergence
        full = run_scenario(variant_scenario, backend=variant)
    assert_same_run(forked, full)
    assert 10 < diverged < reference.frames - 1 and diverged % 10 != 0
    assert not np.array_equal(forked.trajectory["heading"], reference.result.trajectory["heading"])


def test_a_variant_world_must_be_the_reference_world(scenario, reference):
    other = scenario.with_overrides(["seed=99"])
    with ModelBackend(other.params) as variant, pytest.raises(ValueError, match="differ"):
        reference.run_variant(variant, other)
