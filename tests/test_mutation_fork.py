"""The robot judge's forked runs: a mutant's run forked from the unmutated design's gives the
summary and verdict of its full run (``runner.execute``), mutant by mutant, whether the worker
ran the reference itself or was handed it by the worker that did (``reference_share``)."""

import pickle

import pytest
from run_equality import TIMING_FIELDS
from toolchains import needs_mutation_toolchain

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim import mutation

PARAMS = FollowTargetParams(width=80, height=60)


@needs_mutation_toolchain
@pytest.mark.slow  # builds the mutants' Verilator model
def test_forked_mutant_runs_equal_their_full_runs(tmp_path):
    from fpga_robotics.mutation import forked_runs
    from fpga_robotics.mutation.design import WATCH_PORTS_NAME, write_mutant_design
    from fpga_robotics.mutation.forked_runs import execute_forked, outcome_of, reference_share
    from fpga_robotics.mutation.robot_judge import mutant_argv
    from fpga_robotics.sweep import load_campaign, runner
    from fpga_robotics.sweep.plan import make_plan

    listed = mutation.list_mutants(PARAMS, 3000, seed=1)
    # Mutants the robot acts on (wheel commands) and ones it may not (the filtered image,
    # the centroid, the tracker's counters): forked at many frames, or never.
    picks = [
        next(m for m in listed if (m.signal, m.bit, m.mode) == ("motor_left", 12, "inv")),
        next(m for m in listed if m.signal == "filtered__payload" and m.mode == "const1"),
        # A design that stops: its frame never ends (a run that does not pass, on any list).
        next(m for m in listed if (m.signal, m.mode) == ("frame_done", "const0")),
        # A wheel's bit 13 or 14 held at 0: 0 in every forward command; neither wheel
        # reverses in this run, so these mutants never act.
        next(m for m in listed if (m.signal, m.bit, m.mode) == ("motor_left", 13, "const0")),
        next(m for m in listed if (m.signal, m.bit, m.mode) == ("motor_right", 14, "const0")),
    ]
    picks += [m for m in listed if m not in picks][::300][:6]
    chosen = [mutation.Mutant(**{**m.__dict__, "index": i}) for i, m in enumerate(picks, 1)]
    netlist, ports = write_mutant_design(PARAMS, chosen, tmp_path)
    campaign = load_campaign(
        {
            "name": "tiny",
            "scenarios": ["lost_target"],
            "seeds": "0",
            "duration": 3.0,
            "set": ["camera.noise_std=4"],
        }
    )
    spec = make_plan(campaign).runs[0]
    ref_argv = mutant_argv(spec.argv(), netlist, ports, 0, "80x60")
    # The baseline's run, as another worker gets it (pickled), then forgotten here: the
    # mutants' runs below open the reference from it.
    shared = reference_share(ref_argv)
    baseline = runner.execute(ref_argv)
    assert outcome_of(shared)["status"] == baseline["status"] == "pass"
    assert shared["reference"].result.summary["frames"] == baseline["summary"]["frames"]
    shared = pickle.loads(pickle.dumps(shared))
    forked_runs._references.clear()
    verdicts, fulls = set(), {}
    for m in chosen:
        argv = mutant_argv(spec.argv(), netlist, ports, m.index, "80x60")
        fulls[m.index] = full = runner.execute(argv)
        handed = execute_forked(argv, ref_argv, shared=shared)
        forked_runs._references.clear()
        for forked in (handed, execute_forked(argv, ref_argv)):  # the latter runs it here
            assert forked["status"] == full["status"], m.describe()
            if full["summary"] is None:  # the run stopped with an error: the same one
                assert forked["summary"] is None and forked["message"] == full["message"]
            else:
                assert {k: v for k, v in forked["summary"].items() if k not in TIMING_FIELDS} == {
                    k: v for k, v in full["summary"].items() if k not in TIMING_FIELDS
                }, m.describe()
        forked_runs._references.clear()
        verdicts.add(full["status"])
        if full["summary"] is None:  # stopped with an error: no fork record
            assert "fork" not in handed
            continue
        fork, frames = handed["fork"], full["summary"]["frames"]
        if m.index == 1:  # motor_left[12] inverted: parts at once, all of the world again
            assert fork["parted_at"] == fork["world_from"] == 0 and fork["design_ran"]
        if fork["parted_at"] is None:  # the world is the reference's throughout
            assert fork["world_from"] is None and frames == fork["frames"]
        else:  # the world again from a checkpoint (every 30 frames) at or before parting
            assert fork["parted_at"] - 30 < fork["world_from"] <= fork["parted_at"], fork
            assert fork["world_from"] % 30 == 0 and frames == fork["frames"]
    # A passing run and one that did not pass (a failed check, or a design that stopped) compared.
    assert "pass" in verdicts and len(verdicts) > 1, verdicts

    # The reference with the netlist's watch output watched: a mutant that never acted is
    # given the reference's run without its design run, still its full run.
    watch_argv = mutant_argv(spec.argv(), netlist, tmp_path / WATCH_PORTS_NAME, 0, "80x60")
    unrun = 0
    for m in chosen:
        argv = mutant_argv(spec.argv(), netlist, ports, m.index, "80x60")
        forked, full = execute_forked(argv, watch_argv, watch_bit=m.index - 1), fulls[m.index]
        assert forked["status"] == full["status"], m.describe()
        if full["summary"] is not None:
            assert {k: v for k, v in forked["summary"].items() if k not in TIMING_FIELDS} == {
                k: v for k, v in full["summary"].items() if k not in TIMING_FIELDS
            }, m.describe()
            unrun += not forked["fork"]["design_ran"]
    forked_runs._references.clear()
    assert unrun >= 1  # the check above covers a mutant given the reference's run


def test_the_fork_line_counts_runs_and_the_frames_simulated_again():
    from fpga_robotics.cli.mutate import _fork_line

    def fork(parted_at, world_from, ran=True, frames=450):
        return {
            "frames": frames,
            "parted_at": parted_at,
            "world_from": world_from,
            "design_ran": ran,
        }

    verdicts = {
        1: {"forks": [fork(None, None, ran=False), fork(None, None), fork(40, 30)]},
        2: {"forks": [fork(0, 0, frames=300)]},
        3: {"judged_by": "cone", "runs": 0},  # settled: no run, no fork record
        4: None,
    }
    # 4 runs; the world again for 450 - 30 + 300 frames of 1650.
    assert _fork_line(verdicts) == (
        "forked runs: 4; 2 never parted from the unmutated design's (1 without running the "
        "mutant: it never acted); the world simulated again for 720 of 1650 frames (43.6%)"
    )
    assert _fork_line({1: {"runs": 10}}) is None  # --no-fork: no record
