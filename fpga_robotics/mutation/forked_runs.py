"""The robot judge's runs forked from the unmutated design's (fpga_robotics.loop.fork).

Each campaign run goes once with the unmutated design (``mutsel = 0``), on whichever worker:
``reference_share`` returns its outcome with the reference in its portable form
(``ReferenceData``), which the Dask cluster keeps and hands to every mutant's task; a
worker opens each reference once (``ReferenceRun.from_portable``) and keeps it. A mutant's
run of the same scenario is then replayed on the recorded frames and re-simulated only from
where its design drives differently. Its summary and verdict are those of its full run. In
real-clock timing the reference is a ``PinReferenceRun`` (fpga_robotics.loop.pin_fork: the
design's pin calls journaled; ``PinReferenceData`` its portable form). Runs with a shadow
design are run in full (``runner.execute``). When the references
ran with the netlist's watch output watched (the robot judge's ``watch_ports``), a mutant
whose bit never rose in a reference's run (sim.mutant_watch: it never acted there) gets that
run without its design being run.
"""

import uuid

from fpga_robotics.cli import run
from fpga_robotics.loop.fork import ReferenceRun
from fpga_robotics.loop.pin_fork import PinReferenceRun, reference_run
from fpga_robotics.loop.reference_data import PinReferenceData

from ..sweep import runner

__all__ = ["execute_forked", "reference_share"]

#: References a worker keeps (one per campaign run: the mutation campaign has ten).
_KEEP = 16
_references = {}


def _build(ref_argv, outcome=None, timeout=None):
    """The reference run of the unmutated design for ``ref_argv`` (a ``ReferenceRun``, or a
    ``PinReferenceRun`` in real-clock timing), run here, and the watched changes its design
    stopped at (``runner.stops_of``). With ``outcome`` (its ``runner.RunOutcome``) the run,
    not the design's build, is limited to ``timeout`` seconds, as ``runner.execute`` limits
    it."""
    args, scenario, shadow_params = runner.load_run(list(ref_argv))
    design, _ = runner._designs_for(args, scenario, shadow_params)
    run.apply_runtime(design, args)
    runner.set_stop_limit(design, None)  # a kept design may carry a mutant's budget
    deadline = None
    if outcome is not None:
        outcome.deadline = deadline = runner._Deadline(timeout, None)
    reference = reference_run(scenario, design=design, seed=args.seed, progress=deadline)
    return reference, runner.stops_of(design)


def _keep(key, reference, token=None):
    _references.pop(key, None)
    if len(_references) >= _KEEP:
        _references.pop(next(iter(_references)))
    _references[key] = (token, reference)
    return reference


def _reference(ref_argv, shared=None):
    """The worker's ``ReferenceRun`` (``PinReferenceRun``) for ``ref_argv``: opened from
    ``shared`` (its ``reference_share`` result) when given, else run here; once per worker
    either way."""
    key = tuple(ref_argv)
    kept_token, reference = _references.get(key, (None, None))
    if shared is None:
        return reference if reference is not None else _keep(key, _build(ref_argv)[0])
    # The token, not the object: Dask may hand a worker the same result twice.
    if reference is not None and kept_token == shared["token"]:
        return reference
    data = shared["reference"]
    kind = PinReferenceRun if isinstance(data, PinReferenceData) else ReferenceRun
    return _keep(key, kind.from_portable(data), shared["token"])


def _forkable(argv):
    _, scenario, shadow_params = runner.load_run(list(argv))
    return shadow_params is None and scenario.sim.timing in ("compressed", "real_clock")


def reference_share(ref_argv, timeout=None):
    """A run with the unmutated design (the robot judge's baseline): ``{"outcome":
    runner.execute(ref_argv, timeout)'s dict, "reference": its ReferenceData
    (PinReferenceData in real-clock timing), "token": naming this reference}`` (reference
    None for a run that is not forked, erred or timed out). This worker keeps the reference
    opened from that data."""
    if not _forkable(ref_argv):
        return {"outcome": runner.execute(ref_argv, timeout), "reference": None, "token": None}
    shared = {"outcome": None, "reference": None, "token": uuid.uuid4().hex}
    with runner.RunOutcome() as outcome:
        with outcome.running():
            reference, stops = _build(ref_argv, outcome, timeout)
        shared["reference"] = reference.portable()
        # Kept as opened from the data: its images (journal) are the data's, not a copy.
        _reference(ref_argv, shared)
        outcome.record(reference.result)
        outcome.out["design_stops"] = stops
    if outcome.out["summary"] is None:  # it erred: nothing to share
        shared["reference"] = None
    shared["outcome"] = outcome.out
    return shared


def outcome_of(shared):
    """The outcome of a ``reference_share`` result (a task beside it: its data stays put)."""
    return shared["outcome"]


def execute_forked(argv, ref_argv, timeout=None, shared=None, watch_bit=None, stop_limit=None):
    """``runner.execute(argv, timeout)`` for a mutant's run, forked from the reference run
    ``ref_argv`` (the same run with the unmutated design); the same outcome dict, with
    ``"fork"``: the run's ``frames``, the frame its wheels or servos parted from the
    reference's (``parted_at``, None: never), the frame the world was simulated again from
    (``world_from``, None: not at all) and whether its design ran (``design_ran``).
    ``shared``: that run's ``reference_share`` result, whose reference this worker opens
    rather than running it again (None: run here, once per worker). ``watch_bit``: the
    mutant's bit of the netlist's watch output, when the reference ran with it watched
    (sim.mutant_watch: ``mutsel - 1``); a mutant whose bit never rose is not run.
    ``stop_limit``: as ``runner.execute``'s (the forked run counts its design's stops as
    the full run does: each call the design answers live, whether replayed or not)."""
    with runner.RunOutcome() as outcome:
        if not _forkable(ref_argv):
            return runner.execute(argv, timeout=timeout, stop_limit=stop_limit)
        usable = shared is not None and shared["reference"] is not None
        reference = _reference(ref_argv, shared if usable else None)
        args, scenario, shadow_params = runner.load_run(list(argv))
        design, _ = runner._designs_for(args, scenario, shadow_params)
        run.apply_runtime(design, args)
        runner.set_stop_limit(design, stop_limit)
        outcome.deadline = deadline = runner._Deadline(timeout, None)
        try:
            with outcome.running():
                result = reference.run_variant(
                    design, scenario, progress=deadline, watch_bit=watch_bit
                )
        finally:
            outcome.out["design_stops"] = runner.stops_of(design)
        outcome.record(result)
        outcome.out["fork"] = {
            "frames": reference.frames,
            "parted_at": reference.last_divergence,
            "world_from": reference.last_world_from,
            "design_ran": reference.last_design_ran,
        }
    return outcome.out
