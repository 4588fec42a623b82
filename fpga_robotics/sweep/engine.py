"""Running a planned campaign on Dask: an embedded ``LocalCluster`` of worker processes (one
thread each) or an existing scheduler; builds first, then the runs, results as they arrive.

A run's outcome comes back as a row; a run whose worker died (a crash, or the watchdog that
ends a worker stuck inside one frame) comes back as Dask's ``KilledWorker`` and is recorded as
``timeout`` (when the watchdog said so) or ``error``. In a fork group only the run in progress
is: the runs before it keep the outcomes they published, the runs after it are run again.
Ctrl-C cancels what is queued, closes the client and stops an embedded cluster's workers; the
rows so far are kept.
"""

import contextlib
import json
import logging
import os
import shutil
import signal
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

from fpga_robotics.hw.errors import UsageError

from ..sim.files import default_dir_mode, write_atomic
from . import fork_groups, runner
from .results import make_row

__all__ = [
    "DEFAULT_TIMEOUT_FACTOR",
    "MIN_TIMEOUT_S",
    "RECORD_LOG_EVERY",
    "build_all",
    "check_cluster_options",
    "check_scheduler_address",
    "kept_to_record",
    "open_client",
    "run_plan",
]

#: A campaign's recordings log the images of every this many frames (a run's recording at
#: 160x120 is about 45 MB with every frame; the replay command records every frame).
RECORD_LOG_EVERY = 10
#: A run's default timeout is this many times its expected time ...
DEFAULT_TIMEOUT_FACTOR = 10.0
#: ... and never less than this (a loaded machine, a first model load).
MIN_TIMEOUT_S = 30.0
#: Expected seconds per frame and pixel before any run has finished (generous guesses).
_GUESS_S_PER_PIXEL_FRAME = {"pysim": 2e-5}
_GUESS_DEFAULT = 2e-7
_GUESS_PER_FRAME_S = 2e-3


def check_scheduler_address(address):
    """A scheduler address that Dask can dial (``tcp://HOST:PORT``, or another scheme of
    Dask's with a host and port), checked before anything is written: ``UsageError``
    otherwise."""
    from distributed.comm import get_address_host_port  # lazy: Dask costs ~1 s

    try:
        host, _ = get_address_host_port(address)
        if not host:
            raise ValueError("no host")
    except (ValueError, TypeError) as exc:
        raise UsageError(
            f"--scheduler must be a Dask scheduler address tcp://HOST:PORT (e.g. "
            f"tcp://127.0.0.1:8786), got {address!r} ({exc})"
        ) from None


#: The most worker processes an embedded cluster starts (``--workers``).
MAX_WORKERS = 256


def check_cluster_options(workers, scheduler):
    """``--workers`` and ``--scheduler`` as sweep and mutate take them: a worker count in
    1..``MAX_WORKERS``, not both (the embedded cluster's size means nothing with a cluster
    of one's own), and a scheduler address Dask can dial; ``UsageError`` otherwise."""
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise UsageError(f"--workers must be 1..{MAX_WORKERS}, got {workers}")
    if workers is not None and scheduler is not None:
        raise UsageError(
            "--workers sizes the embedded cluster; with --scheduler the cluster "
            "has the workers you started (`dask worker ADDRESS`)"
        )
    if scheduler is not None:
        check_scheduler_address(scheduler)


@contextlib.contextmanager
def open_client(scheduler=None, workers=None):
    """A ``distributed.Client``: to ``scheduler`` (an address), or to a new ``LocalCluster``
    of ``workers`` processes (default: the machine's cores), each with one thread. The
    embedded cluster's scheduler gives up on a run whose worker dies at once (no retry)."""
    import dask  # lazy: Dask costs ~1 s; only a run needs it
    from distributed import Client, LocalCluster  # lazy: Dask costs ~1 s; only a run needs it

    if scheduler is not None:
        check_scheduler_address(scheduler)
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise UsageError(
                f"cannot reach the Dask scheduler at {scheduler!r} ({exc}); start "
                f"one with `dask scheduler` and give its tcp://HOST:PORT"
            ) from None
        try:
            yield client
        finally:
            client.close()
        return
    n = workers or os.cpu_count() or 1
    # Ctrl-C in a terminal reaches the whole process group: the workers ignore it (started
    # with SIGINT ignored, and told again when a nanny restarts one) and this process stops
    # them in order.
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        cluster_cm = _local_cluster(dask, LocalCluster, n)
        cluster = cluster_cm.__enter__()
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        client = Client(cluster)
        try:
            client.register_plugin(_ignore_interrupts_plugin(), name="fpga-robotics-ignore-sigint")
            yield client
        finally:
            client.close()
    finally:
        cluster_cm.__exit__(None, None, None)


@contextlib.contextmanager
def _local_cluster(dask, LocalCluster, n):
    with dask.config.set(
        {
            "distributed.scheduler.allowed-failures": 0,
            "distributed.scheduler.worker-saturation": 1.0,
            "distributed.worker.daemon": False,
            "distributed.admin.system-monitor.gil.enabled": False,
        }
    ):
        cluster = LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            silence_logs=logging.CRITICAL,
        )
    try:
        yield cluster
    finally:
        cluster.close()


def _ignore_interrupts_plugin():
    from distributed import WorkerPlugin  # lazy: Dask costs ~1 s; only a run needs it

    class IgnoreInterrupts(WorkerPlugin):
        """Worker plugin of the embedded cluster: the worker process ignores SIGINT (its
        campaign's process ends it)."""

        def setup(self, worker):
            if threading.current_thread() is threading.main_thread():
                signal.signal(signal.SIGINT, signal.SIG_IGN)

    return IgnoreInterrupts()


class _Timeouts:
    """Per-run timeouts: fixed, or 10x the expected time from the runs finished so far."""

    def __init__(self, fixed):
        self.fixed = fixed
        self.samples = {}

    def learn(self, backend, frames, pixels, run_s):
        if frames > 0 and run_s > 0:
            self.samples.setdefault(backend, []).append(run_s / frames)

    def __call__(self, spec, frames, pixels):
        if self.fixed is not None:
            return self.fixed
        samples = self.samples.get(spec.backend)
        if samples:
            per_frame = statistics.median(samples[-50:])
        else:
            per_frame = _GUESS_PER_FRAME_S + pixels * _GUESS_S_PER_PIXEL_FRAME.get(
                spec.backend, _GUESS_DEFAULT
            )
        return max(MIN_TIMEOUT_S, DEFAULT_TIMEOUT_FACTOR * frames * per_frame)


def _progress(total, quiet):
    from tqdm import tqdm  # lazy: ~0.1 s; only a campaign run shows it

    disable = quiet or bool(os.environ.get("CI")) or not sys.stderr.isatty()
    return tqdm(
        total=total, unit="run", disable=disable, file=sys.stderr, smoothing=0.1, dynamic_ncols=True
    )


def build_all(client, plan):
    """Build (or load from the build cache) every design the plan needs, one task per
    parameter set; returns the seconds each took. A design that cannot be built is the
    user's to fix (``UsageError``)."""
    from distributed import wait  # lazy: Dask costs ~1 s; only a run needs it

    futures = {
        client.submit(runner.build_designs, argv, pure=False): argv for argv in plan.builds.values()
    }
    wait(list(futures))
    times = []
    for fut, argv in futures.items():
        try:
            times.append(fut.result())
        except UsageError as exc:
            raise UsageError(f"building the design of `{' '.join(argv)}`: {exc}") from None
    return times


def run_plan(
    client,
    plan,
    store,
    *,
    record="failing",
    timeout=None,
    quiet=False,
    on_row=None,
    log_every=RECORD_LOG_EVERY,
    bag=False,
    fork=True,
):
    """Run every planned run not already in ``store``, and record the kept ones that lack
    the recording ``record`` asks for (``kept_to_record``); returns the number run.
    Recordings log every ``log_every``-th frame's images (every frame's numbers). With
    ``fork``, runs of one world are run as a reference and forked variants (fork_groups),
    unless every run is recorded."""
    from distributed import as_completed  # lazy: Dask costs ~1 s; only a run needs it

    todo, seen = [], store.done_ids()
    for spec in plan.runs:
        rid = plan.ids[spec]
        if rid not in seen:
            seen.add(rid)
            todo.append(spec)
    to_record = kept_to_record(plan, store, record, bag)
    if not todo and not to_record:
        return 0
    timeouts = _Timeouts(timeout)
    window = max(2, 2 * sum(client.nthreads().values()) or 2)
    if fork and record != "all":
        groups = fork_groups.spread(
            fork_groups.fork_groups(todo, plan.worlds), sum(client.nthreads().values())
        )
    else:
        groups = [[spec] for spec in todo]
    # (specs, recording pass), the last first: the new runs, then the kept runs' recordings.
    pending = [([spec], True) for spec in reversed(to_record)]
    pending += [(group, False) for group in reversed(groups)]
    running = {}  # future -> (specs, submitted at, their timeouts, recording pass)
    # Failing runs waiting for their recording pass: a run's row is stored once, with its
    # recording (results.jsonl holds one line per run). Kept runs to record wait with their
    # kept rows.
    kept = {row["run_id"]: row for row in store.rows}
    awaiting = {plan.ids[spec]: kept[plan.ids[spec]] for spec in to_record}
    failures = 0
    bar = _progress(len(todo), quiet)
    completed = as_completed()

    def submit(specs, recording=False):
        limits = [timeouts(spec, *plan.frames[spec]) for spec in specs]
        key = f"run-{plan.ids[specs[0]]}-{time.monotonic_ns()}"
        if len(specs) > 1:  # one world: a reference run and forked variants
            tags = [f"{key}-{i}" for i in range(len(specs))]
            argvs = [spec.argv() for spec in specs]
            fut = client.submit(fork_groups.execute_group, argvs, limits, tags, pure=False, key=key)
        else:
            rec = log_every if (recording or record == "all") else False
            fut = client.submit(
                runner.execute,
                specs[0].argv(),
                limits[0],
                rec,
                key,
                pure=False,
                key=key,
                bag=bool(bag and rec),
            )
        running[fut] = (specs, time.monotonic(), limits, recording)
        completed.add(fut)

    def top_up():
        while pending and len(running) < window:
            submit(*pending.pop())

    def keep(row, outcome):
        if outcome.get("recording"):
            row["recording"] = _save_recording(store.dir, row["run_id"], outcome["recording"])
        if outcome.get("bag"):
            row["bag"] = _save_bag(store.dir, row["run_id"], outcome["bag"])
        store.add(row)
        if on_row is not None:
            on_row(row)

    def finished(spec, outcome):
        nonlocal failures
        row = make_row(spec, plan.ids[spec], plan.names[spec], outcome)
        if outcome["status"] == "fail" and record == "failing":
            awaiting[row["run_id"]] = row  # stored when its recording pass is back
            submit([spec], recording=True)
        else:
            keep(row, outcome)
        frames, pixels = plan.frames[spec]
        if outcome["status"] in ("pass", "fail", "n/a"):  # a finished run, whatever its verdict
            timeouts.learn(spec.backend, frames, pixels, outcome.get("run_s", 0.0))
        if outcome["status"] != "pass":
            failures += 1
        bar.update(1)
        bar.set_postfix_str(f"{failures} not passed", refresh=False)

    try:
        top_up()
        for fut in completed:
            specs, _submitted, limits, recording = running.pop(fut)
            outcome = _outcome(client, fut, limits)
            if recording:  # the recording pass of a failing run: its row, with the .rrd
                row = awaiting.pop(plan.ids[specs[0]], None)
                if row is not None:  # (a recording pass that failed: the row without one)
                    keep(row, outcome)
                top_up()
                continue
            # A group's task gives one outcome per run (None: not run, its worker died
            # before), or one for all (it never ran: a lost connection, a cancelled task).
            outcomes = outcome if isinstance(outcome, list) else [outcome] * len(specs)
            for spec, each in zip(specs, outcomes, strict=True):
                if each is not None:
                    finished(spec, each)
            not_run = [spec for spec, each in zip(specs, outcomes, strict=True) if each is None]
            if not_run:  # next, as a group of their own
                pending.append((not_run, False))
            top_up()
    finally:
        if running:
            client.cancel(list(running))
        for rid, row in awaiting.items():  # interrupted before their recording: finished runs
            if rid not in kept:
                store.add(row)
        bar.close()
        store.flush()
    return len(todo)


def kept_to_record(plan, store, record, bag):
    """The runs of ``plan`` kept in ``store`` (``--resume``) that lack the recording
    ``record`` asks for (or, with ``bag``, the bag): an earlier campaign ran with less. Runs
    are deterministic, so a recording pass makes them without judging the run again."""
    wanted = {"all": ("pass", "fail", "n/a"), "failing": ("fail",)}.get(record, ())
    files = ("recording", "bag") if bag else ("recording",)
    rows = {row["run_id"]: row for row in store.rows}
    missing = {}
    for spec in plan.runs:
        row = rows.get(plan.ids[spec])
        if row is None or row["status"] not in wanted:
            continue
        if not all(row.get(key) and (store.dir / row[key]).exists() for key in files):
            missing.setdefault(row["run_id"], spec)
    return list(missing.values())


def _timed_out(client, tag):
    """Whether a worker said it ended itself because run ``tag`` was stuck."""
    end = time.monotonic() + 3.0  # the event may arrive just after the worker's death
    while True:
        events = client.get_events(runner.TIMEOUT_TOPIC)
        if any(str(msg.get("tag")) == tag for _t, msg in events):
            return True
        if time.monotonic() > end:
            return False
        time.sleep(0.1)


def _outcome(client, fut, limits):
    """The outcome of a task of ``len(limits)`` runs (their timeouts): one run's, or a
    group's list (``_group_outcomes`` when its worker died)."""
    from distributed import KilledWorker  # lazy: Dask costs ~1 s; only a run needs it

    try:
        return fut.result()
    except KilledWorker:
        if len(limits) > 1:
            return _group_outcomes(client, fut.key, limits)
        return _died(client, fut.key, limits[0])
    except Exception as exc:  # noqa: BLE001 (a lost connection, a cancelled task: recorded)
        return {"status": "error", "message": f"{type(exc).__name__}: {exc}".splitlines()[0]}


def _died(client, tag, limit):
    """The outcome of run ``tag``, whose worker died while running it."""
    if _timed_out(client, tag):
        return {
            "status": "timeout",
            "message": f"no result within the per-run timeout of {limit:.3g} s: the "
            f"run stopped making progress and its worker was ended",
        }
    return {"status": "error", "message": "the worker running it died (a crash or a kill)"}


def _group_outcomes(client, key, limits):
    """The outcomes of a fork group whose worker died: those its runs published
    (fork_groups.MEMBER_TOPIC; they run in order, tagged KEY-<index>), the death for the run
    after the last of them, None for the runs after it (never run)."""
    tags = [f"{key}-{i}" for i in range(len(limits))]
    published = {
        msg.get("tag"): json.loads(msg["outcome"])
        for _t, msg in client.get_events(fork_groups.MEMBER_TOPIC)
        if msg.get("tag") in tags
    }
    outcomes = [published.get(tag) for tag in tags]
    dying = max((i + 1 for i, each in enumerate(outcomes) if each is not None), default=0)
    if dying < len(tags):
        outcomes[dying] = _died(client, tags[dying], limits[dying])
    return outcomes


def _save_bag(out_dir, run_id, files):
    """Write a run's ROS 2 bag (its files) to ``bags/<run_id>/``, whole or not at all."""
    bags = Path(out_dir) / "bags"
    bags.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{run_id}.", dir=bags))
    for name, data in files.items():
        (staging / name).write_bytes(data)
    os.chmod(staging, default_dir_mode())  # mkdtemp's folder is private
    final = bags / run_id
    if final.exists():
        shutil.rmtree(final)
    os.replace(staging, final)
    return str(final.relative_to(out_dir))


def _save_recording(out_dir, run_id, data):
    path = Path(out_dir) / "recordings" / f"{run_id}.rrd"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, data, what="recording")
    return str(path.relative_to(out_dir))
