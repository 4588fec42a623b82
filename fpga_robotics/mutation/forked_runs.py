"""The robot judge's runs forked from the unmutated design's (fpga_robotics.loop.fork).

Each campaign run goes once with the unmutated design (``mutsel = 0``), on whichever worker:
``reference_share`` returns its outcome with the reference in its portable form
(``ReferenceData``), which the Dask cluster keeps and hands to every mutant's task; a
worker opens each reference once (``ReferenceRun.from_portable``) and keeps it. A mutant's
run of the same scenario is then replayed on the recorded frames and re-simulated only from
where its wheel commands part from the reference's. Its summary and verdict are those of its
full run. Runs in real-clock timing or with a shadow design are run in full
(``runner.execute``).
"""

import time
import uuid

from fpga_robotics.cli import run
from fpga_robotics.loop.fork import ReferenceRun, forkable

from ..sweep import runner

__all__ = ["execute_forked", "reference_share"]

#: References a worker keeps (one per campaign run: the mutation campaign has ten).
_KEEP = 16
_references = {}


def _build(ref_argv):
    """The ``ReferenceRun`` of the unmutated design for ``ref_argv``, run here."""
    args, scenario, shadow_params = runner.load_run(list(ref_argv))
    design, _ = runner._designs_for(args, scenario, shadow_params)
    run.apply_runtime(design, args)
    return ReferenceRun(scenario, design=design, seed=args.seed)


def _keep(key, reference, token=None):
    _references.pop(key, None)
    if len(_references) >= _KEEP:
        _references.pop(next(iter(_references)))
    _references[key] = (token, reference)
    return reference


def _reference(ref_argv, shared=None):
    """The worker's ``ReferenceRun`` for ``ref_argv``: opened from ``shared`` (its
    ``reference_share`` result) when given, else run here; once per worker either way."""
    key = tuple(ref_argv)
    kept_token, reference = _references.get(key, (None, None))
    if shared is None:
        return reference if reference is not None else _keep(key, _build(ref_argv))
    # The token, not the object: Dask may hand a worker the same result twice.
    if reference is not None and kept_token == shared["token"]:
        return reference
    return _keep(key, ReferenceRun.from_portable(shared["reference"]), shared["token"])


def _forkable(argv):
    _, scenario, shadow_params = runner.load_run(list(argv))
    return scenario.sim.timing == "compressed" and shadow_params is None and forkable(scenario)


def reference_share(ref_argv):
    """A run with the unmutated design (the robot judge's baseline): ``{"outcome":
    runner.execute(ref_argv)'s dict, "reference": its ReferenceData, "token": naming this
    reference}`` (reference None for a run that is not forked or erred). This worker keeps
    the reference opened from that data."""
    if not _forkable(ref_argv):
        return {"outcome": runner.execute(ref_argv), "reference": None, "token": None}
    wall0, cpu0 = time.perf_counter(), time.process_time()
    out = {"status": "error", "message": "", "summary": None, "recording": None, "run_s": 0.0}
    shared = {"outcome": out, "reference": None, "token": uuid.uuid4().hex}
    try:
        reference = _build(ref_argv)
        out["run_s"] = time.perf_counter() - wall0
        shared["reference"] = reference.portable()
        # Kept as opened from the data: its images are the data's, not a second copy.
        _reference(ref_argv, shared)
        summary = dict(reference.result.summary)
        out.update(status=summary["verdict"], summary=summary)
    except Exception as exc:  # noqa: BLE001 (recorded as the baseline's error)
        out.update(status="error", message=f"{type(exc).__name__}: {exc}".splitlines()[0])
        shared["reference"] = None
    out["wall_s"] = time.perf_counter() - wall0
    out["cpu_s"] = time.process_time() - cpu0
    return shared


def outcome_of(shared):
    """The outcome of a ``reference_share`` result (a task beside it: its data stays put)."""
    return shared["outcome"]


def execute_forked(argv, ref_argv, timeout=None, shared=None):
    """``runner.execute(argv, timeout)`` for a mutant's run, forked from the reference run
    ``ref_argv`` (the same run with the unmutated design); the same outcome dict.
    ``shared``: that run's ``reference_share`` result, whose reference this worker opens
    rather than running it again (None: run here, once per worker)."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    out = {"status": "error", "message": "", "summary": None, "recording": None, "run_s": 0.0}
    deadline = None
    try:
        if not _forkable(ref_argv):
            return runner.execute(argv, timeout=timeout)
        usable = shared is not None and shared["reference"] is not None
        reference = _reference(ref_argv, shared if usable else None)
        args, scenario, shadow_params = runner.load_run(list(argv))
        design, _ = runner._designs_for(args, scenario, shadow_params)
        run.apply_runtime(design, args)
        deadline = runner._Deadline(timeout, None)
        t_run = time.perf_counter()
        result = reference.run_variant(design, scenario, progress=deadline)
        out["run_s"] = time.perf_counter() - t_run
        out.update(status=result.summary["verdict"], summary=dict(result.summary))
    except runner.RunTimeout as exc:
        out.update(status="timeout", message=str(exc))
    except Exception as exc:  # noqa: BLE001 (the mutant's run errs: it is caught)
        out.update(status="error", message=f"{type(exc).__name__}: {exc}".splitlines()[0])
    finally:
        if deadline is not None:
            deadline.cancel()
    out["wall_s"] = time.perf_counter() - wall0
    out["cpu_s"] = time.process_time() - cpu0
    return out
