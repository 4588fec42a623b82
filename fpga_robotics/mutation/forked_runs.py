"""The robot judge's runs forked from the unmutated design's (fpga_robotics.loop.fork).

A worker runs each campaign run once with the unmutated design (``mutsel = 0``) and keeps it
as a ``ReferenceRun``; a mutant's run of the same scenario is then replayed on the recorded
frames and re-simulated only from where its wheel commands part from the reference's. Its
summary and verdict are those of its full run. Runs in real-clock timing or with a shadow
design are run in full (``runner.execute``).
"""

import time

from fpga_robotics.cli import run
from fpga_robotics.loop.fork import ReferenceRun, forkable

from ..sweep import runner

__all__ = ["execute_forked", "reference_outcome"]

#: References a worker keeps (one per campaign run: the mutation campaign has nine).
_KEEP = 16
_references = {}


def _reference(ref_argv):
    """The worker's ``ReferenceRun`` of the unmutated design for ``ref_argv`` (built once)."""
    key = tuple(ref_argv)
    if key not in _references:
        if len(_references) >= _KEEP:
            _references.pop(next(iter(_references)))
        args, scenario, shadow_params = runner.load_run(list(ref_argv))
        design, _ = runner._designs_for(args, scenario, shadow_params)
        run.apply_runtime(design, args)
        _references[key] = ReferenceRun(scenario, design=design, seed=args.seed)
    return _references[key]


def _forkable(argv):
    _, scenario, shadow_params = runner.load_run(list(argv))
    return scenario.sim.timing == "compressed" and shadow_params is None and forkable(scenario)


def reference_outcome(ref_argv):
    """``runner.execute(ref_argv)`` of a run with the unmutated design, which the worker keeps
    as the reference of the mutants' runs (the robot judge's baseline)."""
    if not _forkable(ref_argv):
        return runner.execute(ref_argv)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    out = {"status": "error", "message": "", "summary": None, "recording": None, "run_s": 0.0}
    try:
        summary = dict(_reference(ref_argv).result.summary)
        out.update(status=summary["verdict"], summary=summary, run_s=time.perf_counter() - wall0)
    except Exception as exc:  # noqa: BLE001 (recorded as the baseline's error)
        out.update(status="error", message=f"{type(exc).__name__}: {exc}".splitlines()[0])
    out["wall_s"] = time.perf_counter() - wall0
    out["cpu_s"] = time.process_time() - cpu0
    return out


def execute_forked(argv, ref_argv, timeout=None):
    """``runner.execute(argv, timeout)`` for a mutant's run, forked from the reference run
    ``ref_argv`` (the same run with the unmutated design); the same outcome dict."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    out = {"status": "error", "message": "", "summary": None, "recording": None, "run_s": 0.0}
    deadline = None
    try:
        if not _forkable(ref_argv):
            return runner.execute(argv, timeout=timeout)
        reference = _reference(ref_argv)
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
