"""In compressed timing the pan camera's channel runs on the chosen backend: on pysim, cxxrtl
and verilator the design itself (fpga_robotics.loop.pin_channel), and it gives the numpy
model's servo commands and turret outputs frame for frame, its search included."""

import numpy as np
import pytest

from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario

COLUMNS = ("turret.turret_found", "turret.turret_centroid_x", "pan.command", "pan.angle_deg")


def run(backend, overrides):
    r = run_scenario(load_scenario("turret", overrides), backend=backend)
    return r.summary["cameras"]["turret"]["channel"], {c: r.trajectory[c] for c in COLUMNS}


def assert_same(model, design):
    for column in COLUMNS:
        np.testing.assert_array_equal(design[column], model[column], err_msg=column)


def test_pysim_runs_the_pan_channel_on_the_design_as_the_model_does():
    overrides = ["sim.duration=0.3"]
    ran, model = run("model", overrides)
    assert ran == "model"
    ran, design = run("pysim", overrides)
    assert ran == "pysim"
    assert len(np.unique(model["pan.command"])) > 2  # the servo turns in these frames
    assert_same(model, design)


@pytest.mark.slow  # builds the compiled models of TurretTracker
@pytest.mark.parametrize("backend", ["cxxrtl", "verilator"])
def test_compiled_backends_run_the_pan_channel_and_its_search_as_the_model(backend):
    # A quick search (after 2 lost frames, 40 units a frame) so that the red person's passes
    # in front of the blue one start searches within 8 s.
    overrides = ["sim.duration=8", "design.turret.lost_frames=2", "design.turret.search_step=40"]
    _, model = run("model", overrides)
    lost = model["turret.turret_found"] == 0
    command = model["pan.command"]
    searched = lost[1:] & lost[:-1] & (np.diff(command) != 0)
    assert searched.sum() >= 3  # the search moved the servo in lost frames
    ran, design = run(backend, overrides)
    assert ran == backend
    assert_same(model, design)
