"""``run_campaign``: plan, build, run and report a campaign (the command's and the API's
one code path)."""

import shutil
import time
from pathlib import Path

from fpga_robotics.hw.errors import UsageError

from .. import __version__
from .engine import RECORD_LOG_EVERY, build_all, kept_to_record, open_client, run_plan
from .plan import make_plan
from .report import campaign_passed, format_report, write_html
from .results import ResultStore, load_rows, read_meta, write_meta

__all__ = ["dir_passed", "report_dir", "run_campaign", "wait_for_a_worker"]


def run_campaign(
    campaign,
    out_dir,
    *,
    workers=None,
    scheduler=None,
    resume=False,
    record="failing",
    timeout=None,
    max_runs=None,
    quiet=True,
    client=None,
    echo=None,
    log_every=RECORD_LOG_EVERY,
    bag=False,
    fork=True,
):
    """Run ``campaign`` (a ``Campaign``) and return its results rows (list of dicts, one per
    run, in the order they finished; with ``resume`` the rows already in ``out_dir`` of runs
    of this campaign too: a row whose run's identity changed is dropped and run again).

    ``client``: an open ``distributed.Client`` to use (else one is opened: ``scheduler`` or
    an embedded cluster of ``workers`` processes). ``echo(text)``: where progress notes go.
    ``bag``: the recorded runs (``record``) are also written as ROS 2 bags, ``bags/<run_id>/``
    (docs/ros.md). ``fork``: runs that differ only in their design run as one reference
    run and forked variants (fork_groups; the same rows), False runs each in full.
    """
    say = echo or (lambda text: None)
    if timeout is None:  # the campaign file's `timeout`, unless the caller gives one
        timeout = campaign.timeout
    plan = make_plan(campaign)
    # --resume keeps the finished runs of the whole campaign (--max-runs limits what runs now).
    run_ids = set(plan.ids.values())
    if max_runs is not None:
        plan.keep_first(max_runs)
    out_dir = Path(out_dir)
    # The folders this call makes: removed again when it fails before any run finished (a
    # folder that was there, with results --resume could use, is never removed).
    made = _first_missing(out_dir)
    meta = {
        "name": campaign.name,
        "description": campaign.description,
        "source": campaign.source,
        "axes": campaign.axes,
        "runs": len(plan.runs),
        "backend": sorted({s.backend for s in plan.runs}),
        "version": __version__,
        "scheduler": scheduler,
        "workers": workers,
        "known_limits": campaign.known_limits,
    }
    t0 = time.perf_counter()
    store = None
    try:
        with (
            _given(client)
            if client is not None
            else open_client(scheduler=scheduler, workers=workers)
        ) as c:
            wait_for_a_worker(c, scheduler)
            t_build = time.perf_counter()
            builds = build_all(c, plan)
            meta["build_s"] = round(time.perf_counter() - t_build, 3)
            meta["build_s_each"] = [round(b, 3) for b in builds]
            say(f"built or loaded {len(builds)} design(s) in {meta['build_s']:.1f} s")
            # The folder only once the cluster is there and every design built: an
            # unreachable scheduler, a design that does not build or a Ctrl-C before the
            # runs leave the folder as it was.
            store = ResultStore(out_dir, resume=resume, run_ids=run_ids)
            if resume and store.dropped:
                say(
                    f"--resume: {store.dropped} earlier row(s) in {out_dir} not kept "
                    f"(errors, timeouts, and runs this campaign no longer makes: an edited "
                    f"scenario or design file, another option or package version)"
                )
            done = store.done_ids()
            already = len({plan.ids[s] for s in plan.runs} & done)
            if already:
                say(
                    f"{already} of {len(plan.runs)} runs already in {out_dir} (--resume): "
                    f"running the other {len(plan.runs) - already}"
                )
            unrecorded = len(kept_to_record(plan, store, record, bag))
            if unrecorded:
                what = "recording or bag" if bag else "recording"
                say(
                    f"recording {unrecorded} kept run(s) that have no {what} "
                    f"(--record {record}{' --bag' if bag else ''})"
                )
            t_runs = time.perf_counter()
            meta["ran"] = run_plan(
                c,
                plan,
                store,
                record=record,
                timeout=timeout,
                quiet=quiet,
                log_every=log_every,
                bag=bag,
                fork=fork,
            )
            meta["runs_wall_s"] = round(time.perf_counter() - t_runs, 3)
            meta["workers"] = len(c.scheduler_info()["workers"])
    except Exception:
        if store is not None:
            store.close()
        if made is not None and (store is None or not store.rows):
            shutil.rmtree(made, ignore_errors=True)
            store = None
        raise
    finally:
        if store is not None:
            store.close()
            meta["wall_s"] = round(time.perf_counter() - t0, 3)
            # Runs that never ran (an interrupted campaign): the report counts them.
            meta["missing"] = len({plan.ids[s] for s in plan.runs} - store.done_ids())
            write_meta(out_dir, meta)
            if store.rows:
                _write_report(out_dir, store.rows, campaign.axes, meta)
            else:  # an earlier campaign's report would describe rows no longer there
                (out_dir / "report.html").unlink(missing_ok=True)
    return store.rows


def _write_report(out_dir, rows, axes, meta):
    path = out_dir / "report.html"
    try:
        write_html(path, rows, axes, meta)
    except KeyboardInterrupt:
        # Interrupted while drawing: no report rather than an earlier one that no longer
        # describes the results (`sweep report DIR` draws it).
        path.unlink(missing_ok=True)
        raise


def _first_missing(path):
    """The outermost folder of ``path`` that does not exist yet (None: ``path`` exists)."""
    missing = None
    for folder in (path, *path.parents):
        if folder.exists():
            break
        missing = folder
    return missing


#: How long a campaign waits for a first worker to join an existing scheduler.
WORKER_WAIT_S = 60


def wait_for_a_worker(client, scheduler):
    """Wait (``WORKER_WAIT_S``) for a first worker; a scheduler without one is the user's to
    fix (``UsageError`` saying how to start workers)."""
    try:
        client.wait_for_workers(1, timeout=WORKER_WAIT_S)
    except TimeoutError:
        raise UsageError(
            f"no Dask worker joined the scheduler {scheduler} within "
            f"{WORKER_WAIT_S} s; start workers with `dask worker {scheduler}`"
        ) from None


class _given:
    def __init__(self, client):
        self.client = client

    def __enter__(self):
        return self.client

    def __exit__(self, *exc):
        return False


def report_dir(out_dir):
    """Rebuild ``report.html`` in ``out_dir`` from its results; returns the terminal summary."""
    out_dir = Path(out_dir)
    rows = load_rows(out_dir)
    if not rows:
        raise UsageError(
            f"{out_dir} holds no campaign results (results.jsonl or "
            f"results.parquet); run a campaign with --out {out_dir} first"
        )
    meta = read_meta(out_dir)
    axes = meta.get("axes") or sorted(
        {k for r in rows for k in r if "." in k and not k.startswith(("check_", "collisions_"))}
    )
    write_html(out_dir / "report.html", rows, axes, meta)
    return format_report(rows, axes, meta.get("known_limits") or (), meta.get("missing", 0))


def dir_passed(out_dir):
    """Whether the campaign in ``out_dir`` passed: every one of its runs is there (none
    missing from an interruption) and passed, or failed only where a known limit explains it
    (the exit code of ``sweep report``, as of the campaign itself)."""
    out_dir = Path(out_dir)
    meta = read_meta(out_dir)
    rows = load_rows(out_dir)
    return not meta.get("missing", 0) and campaign_passed(rows, meta.get("known_limits") or ())
