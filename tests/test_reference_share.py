"""A reference run in its portable form (``ReferenceRun.portable``), pickled and opened again,
judges variants exactly as the reference itself: in this process, and in a fresh one that
never ran the reference (its renderer, terrain and design are its own)."""

import dataclasses
import multiprocessing
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest
from run_equality import assert_same_run
from test_fork import Altered, _left_plus
from test_fork_rig import LATE_CAPTURE, altered_tops  # noqa: F401 (the altered turret tops)
from toolchains import needs_mutation_toolchain

from fpga_robotics.loop import checkpoint
from fpga_robotics.loop.compressed import ClosedLoop
from fpga_robotics.loop.fork import ReferenceRun
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario
from fpga_robotics.sim.backends.model import ModelBackend

# A noisy camera and a target that walks away; terrain patches under the robot; a low-grip
# floor; the divider's furniture: every kind of shared object a checkpoint names.
SCENARIOS = ["lost_target", "ramp", "slippery", "divider"]
OVERRIDES = ["sim.duration=2.5", "camera.noise_std=4"]


def _variants(params, frames):
    """(name, design): one that never drives differently (found never reported), one that
    parts at frame 0, one that parts two frames before the end."""
    return [
        ("never", Altered(params, lambda k, r: dataclasses.replace(r, found=False, proximity=0))),
        ("first", Altered(params, _left_plus(0))),
        ("late", Altered(params, _left_plus(frames - 2))),
    ]


def _judged(reference, scenario):
    """``{name: (RunResult, divergence frame)}`` of the variants against ``reference``."""
    out = {}
    for name, variant in _variants(scenario.params, reference.frames):
        result = reference.run_variant(variant)
        out[name] = (result, reference.last_divergence)
    return out


def _judged_elsewhere(blob):
    """In a fresh process: the variants judged against the pickled portable reference."""
    reference = ReferenceRun.from_portable(pickle.loads(blob))
    return _judged(reference, reference.scenario)


@pytest.fixture(scope="module", params=SCENARIOS)
def shared(request):
    scenario = load_scenario(request.param, OVERRIDES)
    with ModelBackend(scenario.params) as design:
        reference = ReferenceRun(scenario, design=design, checkpoint_every=7)
    blob = pickle.dumps(reference.portable())
    return scenario, reference, blob


def test_the_portable_reference_judges_as_the_reference(shared):
    scenario, reference, blob = shared
    opened = ReferenceRun.from_portable(pickle.loads(blob))
    assert opened.frames == reference.frames and opened.seed == reference.seed
    assert_same_run(opened.result, reference.result)
    mine, theirs = _judged(reference, scenario), _judged(opened, scenario)
    assert [d for _, d in mine.values()] == [None, 0, reference.frames - 2]
    for name, (result, diverged) in theirs.items():
        assert diverged == mine[name][1], name
        assert_same_run(result, mine[name][0])


def test_a_portable_turret_reference_judges_as_the_reference():
    # A servo and a pan camera: the further camera's captures and the servo commands travel
    # with the reference; its channel's state is the variant's own on restore.
    scenario = load_scenario("turret", ["sim.duration=6"])
    with ModelBackend(scenario.params) as design:
        reference = ReferenceRun(scenario, design=design, checkpoint_every=7)
    data = reference.portable()
    assert data.captures and data.rig_interface is not None
    opened = ReferenceRun.from_portable(pickle.loads(pickle.dumps(data)))
    diverged = []
    for overrides in (
        ["design.top=turret_neverfound"],  # never parts
        ["design.variant=turret_pan_inverted"],  # the servo from the first frame
        ["design.top=turret_servoplus"],  # the servo, late
    ):
        variant = scenario.with_overrides(overrides)
        with ModelBackend(variant.params) as design:
            mine = reference.run_variant(design, variant)
            theirs = opened.run_variant(design, variant)
        assert opened.last_divergence == reference.last_divergence, overrides
        assert_same_run(theirs, mine)
        diverged.append(opened.last_divergence)
    assert diverged == [None, 0, LATE_CAPTURE]


def test_a_fresh_process_judges_as_the_full_runs():
    # The one process the reference never ran in: each variant's result is its full run.
    scenario = load_scenario("ramp", OVERRIDES)
    with ModelBackend(scenario.params) as design:
        reference = ReferenceRun(scenario, design=design, checkpoint_every=7)
    blob = pickle.dumps(reference.portable())
    spawn = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(1, mp_context=spawn) as pool:
        elsewhere = pool.submit(_judged_elsewhere, blob).result(timeout=600)
    for name, variant in _variants(scenario.params, reference.frames):
        result, diverged = elsewhere[name]
        assert_same_run(result, run_scenario(scenario, backend=variant))
        assert (diverged is None) == (name == "never"), name
    # The late variant re-simulated from a checkpoint, not from the start.
    assert elsewhere["late"][1] == reference.frames - 2 > 7


def test_the_images_are_one_buffer():
    scenario = load_scenario("lost_target", ["sim.duration=1"])
    with ModelBackend(scenario.params) as design:
        reference = ReferenceRun(scenario, design=design)
    data = reference.portable()
    cam = scenario.camera
    assert data.frames.shape == (reference.frames, cam.height, cam.width, 3)
    assert data.frames.dtype == np.uint8 and data.frames.flags.c_contiguous
    opened = ReferenceRun.from_portable(data)
    for (rgb, color), (mine, my_color) in zip(opened._loop.seen, reference._loop.seen):
        assert np.shares_memory(rgb, data.frames) and np.array_equal(rgb, mine)
        assert color == my_color
    assert data.nbytes > data.frames.nbytes


def test_a_checkpoint_restores_only_into_its_own_scenario():
    # The ramp's terrain has patches the flat floor lacks: the shared objects do not match.
    ramp = load_scenario("ramp", ["sim.duration=0.5"])
    flat = load_scenario("follow_person", ["sim.duration=0.5"])
    with ModelBackend(ramp.params) as design:
        design.reset()
        saved = checkpoint.portable(checkpoint.take(ClosedLoop(ramp, design=design)))
        with pytest.raises(ValueError, match="its own scenario"):
            checkpoint.restore(ClosedLoop(flat, design=design), saved)
        # Into a loop of its own scenario it restores (the state it was taken with).
        loop = ClosedLoop(ramp, design=design)
        checkpoint.restore(loop, saved)
        assert loop.frames_done == saved.frame == 0


@needs_mutation_toolchain
@pytest.mark.slow  # builds the mutants' Verilator model
def test_two_workers_judge_against_the_same_references(tmp_path):
    """The robot judge on two Dask workers: every worker holds the baseline's references, the
    same ones (each run once, by one worker), and the verdicts are those of full runs."""
    from distributed import Client, LocalCluster

    from fpga_robotics.hw.params import FollowTargetParams
    from fpga_robotics.mutation.design import write_mutant_design
    from fpga_robotics.mutation.robot_judge import robot_judge
    from fpga_robotics.mutation.same_verdicts import differing_verdicts, read_journal
    from fpga_robotics.sim import mutation
    from fpga_robotics.sweep import load_campaign

    params = FollowTargetParams(width=80, height=60)
    listed = mutation.list_mutants(params, 3000, seed=1)
    picks = [
        next(m for m in listed if (m.signal, m.bit, m.mode) == ("motor_left", 12, "inv")),
        next(m for m in listed if m.signal == "filtered__payload" and m.mode == "const1"),
    ]
    picks += [m for m in listed if m not in picks][::500][:4]
    chosen = [mutation.Mutant(**{**m.__dict__, "index": i}) for i, m in enumerate(picks, 1)]
    netlist, ports = write_mutant_design(params, chosen, tmp_path)
    campaign = load_campaign(
        {"name": "tiny", "scenarios": ["follow_person", "lost_target"], "seeds": "0", "duration": 3}
    )
    indices = [m.index for m in chosen]
    judged = {}
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        for fork in (True, False):
            out = tmp_path / ("forked" if fork else "full")
            out.mkdir()
            baseline, _ = robot_judge(
                campaign,
                netlist,
                ports,
                "80x60",
                indices,
                str(out),
                scheduler=cluster.scheduler_address,
                say=lambda text: None,
                fork=fork,
            )
            judged[fork] = read_journal(str(out))
            if fork:
                # Each worker's references, by the token of the baseline run that made them
                # (None: one it ran itself).
                kept = client.run(
                    lambda: [
                        token
                        for token, _ in __import__(
                            "fpga_robotics.mutation.forked_runs", fromlist=["_references"]
                        )._references.values()
                    ]
                )
    assert len(baseline["passing"]) == 2
    tokens = [sorted(t) for t in kept.values()]
    assert len(tokens) == 2 and tokens[0] == tokens[1] and None not in tokens[0]
    assert len(tokens[0]) == 2
    assert differing_verdicts(judged[True], judged[False]) == []
    assert {v["caught"] for v in judged[True].values()} == {True, False}


def test_a_reference_run_over_its_timeout_is_a_timeout_and_shares_nothing():
    # The robot judge's unmutated runs take the campaign file's timeout (it was ignored).
    from fpga_robotics.mutation.forked_runs import reference_share

    argv = ["--scenario", "lost_target", "--backend", "model", "--resolution", "80x60"]
    argv += ["--duration", "1.0"]
    for run in (argv, [*argv, "--shadow", "lost_frames=5"]):  # forked, and run in full
        shared = reference_share(run, 1e-6)
        assert shared["outcome"]["status"] == "timeout" and shared["reference"] is None
        assert "per-run timeout" in shared["outcome"]["message"]
        assert reference_share(run)["outcome"]["status"] != "timeout"
