"""One run of a campaign, from its ``run`` argument list to its result row.

The argument list is parsed by ``fpga_robotics.run``'s own parser and turned into a scenario,
a design and a shadow by ``run``'s own helpers, then ``loop.run_scenario`` runs it: a row's
replay command (``python -m fpga_robotics.run`` + the same arguments) is the same run.

These functions are the Dask tasks (importable, never defined in ``__main__``). A worker
process keeps the designs it opened (a compiled model is loaded once, reset before each run).

Test hook (not a user option): ``FPGA_ROBOTICS_SWEEP_FAULT="raise@SEED,exit@SEED,hang@SEED"``
in a worker's environment makes the run of that seed raise, end its worker process, or stop
making progress, at its first frame (``exit@SEED+KEY=VALUE``: only the runs of that seed
with that ``--set`` item); the test suite uses it to check that a campaign records such runs
and goes on.
"""

import argparse
import contextlib
import hashlib
import os
import shutil
import tempfile
import threading
import time
from pathlib import Path

from fpga_robotics.hw.errors import UsageError

__all__ = [
    "TIMEOUT_TOPIC",
    "RunOutcome",
    "RunTimeout",
    "build_designs",
    "design_digest",
    "execute",
    "load_run",
    "set_stop_limit",
    "stops_of",
]

#: The Dask event topic under which a worker says it ends itself for a stuck run (the client
#: then records that run as ``timeout``, not as a crash).
TIMEOUT_TOPIC = "fpga-robotics-sweep-timeouts"

#: Designs a worker keeps open (a campaign has few parameter sets per worker at a time).
_KEEP = 4
_designs = {}

#: How much longer than the per-run timeout (at most, and at most the timeout again) a run
#: stuck inside one frame may take before its worker process is ended (a run stuck in
#: compiled code cannot be interrupted otherwise).
HARD_GRACE_S = 10.0


class RunTimeout(Exception):
    """The run took longer than its timeout."""


def _loaded(argv):
    """``load_run`` of the runs of a worker, remembered by their arguments other than the
    seed (the scenario does not depend on it): a campaign's runs differ mostly by seed."""
    argv = list(argv)
    i = argv.index("--seed") if "--seed" in argv else None
    seed = argv[i + 1] if i is not None else None
    shape = tuple(argv[:i] + argv[i + 2 :]) if i is not None else tuple(argv)
    if shape not in _loads:
        if len(_loads) >= 64:
            _loads.clear()
        _loads[shape] = load_run(list(shape))
    args, scenario, shadow_params = _loads[shape]
    args = argparse.Namespace(**vars(args))
    if seed is not None:
        args.seed = int(seed)
        from fpga_robotics.scenario.load import MAX_SEED  # lazy: the run stack (~1 s)

        if not 0 <= args.seed <= MAX_SEED:
            raise UsageError(f"--seed must be in 0..{MAX_SEED}, got {args.seed}")
    return args, scenario, shadow_params


_loads = {}


def load_run(argv):
    """``(args, scenario, shadow_params)`` of a run, checked as ``run`` checks them
    (``UsageError`` with one line when something is wrong). ``shadow_params``: the
    ``--shadow``'s FollowTarget parameters, or for a shadow design (``--shadow REF``,
    real-clock timing) the scenario that runs it; None without a shadow."""
    from fpga_robotics.cli import run  # lazy: the run stack (~1 s)
    from fpga_robotics.loop.real_clock import check_pin_backend  # lazy: the run stack (~1 s)
    from fpga_robotics.scenario.load import (  # lazy: the run stack (~1 s)
        MAX_SEED,
    )

    args = run.build_parser().parse_args(argv)
    args.quiet = True
    if args.seed is not None and not 0 <= args.seed <= MAX_SEED:
        raise UsageError(f"--seed must be in 0..{MAX_SEED}, got {args.seed}")
    scenario = run.load_run_scenario(args)
    run.take_design_reference(args, scenario)
    # As run takes --shadow: a design reference is a second design on pins, else
    # FollowTarget parameters, which compare frames.
    shadow_params, params_scenario = run.shadow_designs(args, scenario)
    if params_scenario is not None:
        shadow_params = params_scenario.params
    run._design_files(args, scenario.foreign)
    if scenario.sim.timing == "real_clock":  # the pin design is the scenario's foreign one
        check_pin_backend(args.backend)  # the build would refuse it: a dry run too
        scenario = run._with_design_files(args, scenario)
    return args, scenario, shadow_params


def _design_key(args, scenario):
    return (
        "design",
        args.backend,
        args.design,
        args.ports,
        repr(scenario.foreign),
        repr(scenario.params),
        scenario.sim.timing,
        scenario.top,
        repr(sorted(scenario.design_tables.items())),
        repr(sorted(scenario.design_params.items())),
    )


def design_digest(args, scenario, shadow=None):
    """sha256 of a run's designs as they are built, for the run's identity: a Verilog
    design's files, port map, the files they `include (as the build cache hashes them) and
    its parameters and macros; a
    design of one's own: its file and its netlist as elaborated (whatever its file imports or
    reads). A built-in design is the package's: its version names it. ``shadow``: the
    scenario of a shadow design."""
    from fpga_robotics.cli import run  # lazy: the run stack (~1 s)
    from fpga_robotics.designs.reference import is_builtin, resolve_design  # lazy: as run
    from fpga_robotics.sim.backends.foreign import verilog_includes  # lazy: as run

    h = hashlib.sha256()
    designs = [(scenario, run._design_files(args, scenario.foreign))]
    if shadow is not None:
        foreign = shadow.foreign
        designs.append((shadow, None if foreign is None else (foreign.verilog, foreign.ports)))
    for of, verilog in designs:
        if verilog is not None:
            files, ports = verilog
            paths = [Path(f).expanduser() for f in files]
            for path in [*paths, Path(ports).expanduser()]:
                h.update(_content(path))
            for name, text in sorted(verilog_includes(paths).items()):
                h.update(f"{name}\0{text}\0".encode())
            # Its parameters and macros: another build of the same files.
            h.update(repr(of.foreign.overrides if of.foreign else None).encode())
        elif not is_builtin(of.top):
            # Its file, as a Verilog design's (any edit makes another run), and its netlist:
            # what the modules it imports and the files it reads make of it.
            where = of.top.rpartition(":")[0]
            if where.endswith(".py"):
                h.update(_content(Path(where)))
            h.update(resolve_design(of.top, of.design_params).netlist_digest.encode())
    return h.hexdigest()


def _content(path):
    """A file's bytes; its name when it cannot be read (the build says why)."""
    try:
        return path.read_bytes() + b"\0"
    except OSError:
        return f"{path}\0".encode()


def _open(key, opener):
    design = _designs.pop(key, None)
    if design is None:
        design = opener()
    _designs[key] = design  # most recently used last
    while len(_designs) > _KEEP:
        old = _designs.pop(next(iter(_designs)))
        old.close()
    return design


def _designs_for(args, scenario, shadow_params):
    from fpga_robotics.cli import run  # lazy: the run stack (~1 s)

    if scenario.sim.timing == "real_clock":  # a pin-level backend (fpga_robotics.loop.real_clock)
        design = _open(_design_key(args, scenario), lambda: run._open_pin_design(args, scenario))
    else:
        design = _open(
            _design_key(args, scenario),
            lambda: run._open_design(args, scenario),
        )
    shadow = None
    name = args.shadow_backend or args.backend
    if hasattr(shadow_params, "sim"):  # a shadow design: its scenario, on pins
        shadow_args = run._shadow_args(args, shadow_params)
        shadow = _open(
            ("shadow", *_design_key(shadow_args, shadow_params)),
            lambda: run._open_pin_design(shadow_args, shadow_params, f"--shadow {args.shadow}"),
        )
    elif shadow_params is not None:
        shadow = _open(
            ("shadow", name, repr(shadow_params)),
            lambda: run._open_backend(name, shadow_params, True),
        )
    return design, shadow


def build_designs(argv):
    """Build (or find in the build cache) the design and shadow of a run; returns seconds.
    Called once per parameter set before the runs are dispatched."""
    t0 = time.perf_counter()
    args, scenario, shadow_params = load_run(argv)
    _designs_for(args, scenario, shadow_params)
    return time.perf_counter() - t0


def _fault(args):
    spec = os.environ.get("FPGA_ROBOTICS_SWEEP_FAULT", "")
    for item in filter(None, (s.strip() for s in spec.split(","))):
        kind, _, at = item.partition("@")
        seed, _, override = at.partition("+")
        if seed.strip() == str(args.seed) and (not override or override in args.overrides):
            return kind.strip()
    return None


class _Deadline:
    """The progress callback: raises ``RunTimeout`` once the run is over its time; a
    watchdog ends the worker process if a single frame hangs past a hard limit."""

    def __init__(self, timeout, fault, tag=None):
        self.timeout = timeout
        self.fault = fault
        self.tag = tag
        self.start = time.perf_counter()
        self.watchdog = None
        self.worker = _current_worker()
        if timeout is not None:
            grace = min(HARD_GRACE_S, max(1.0, timeout))
            self.watchdog = threading.Timer(timeout + grace, self._expire)
            self.watchdog.daemon = True
            self.watchdog.start()

    def __call__(self, done, total):
        if self.fault is not None and done == 1:
            if self.fault == "raise":
                raise RuntimeError("injected fault (FPGA_ROBOTICS_SWEEP_FAULT)")
            if self.fault == "exit":
                os._exit(70)
            if self.fault == "hang":
                time.sleep(10**6)
        if self.timeout is not None and time.perf_counter() - self.start > self.timeout:
            raise RunTimeout(
                f"no result within the per-run timeout of {self.timeout:.3g} s "
                f"(frame {done} of {total})"
            )

    def _expire(self):
        """End this worker process (its nanny starts a new one), telling the scheduler why."""
        if self.worker is not None and self.tag is not None:
            self.worker.log_event(TIMEOUT_TOPIC, {"tag": self.tag})
            time.sleep(1.0)  # the event is sent in the background
        os._exit(75)

    def cancel(self):
        if self.watchdog is not None:
            self.watchdog.cancel()


def _current_worker():
    try:
        from distributed import get_worker  # lazy: Dask costs ~1 s; only a run needs it

        return get_worker()
    except (ImportError, ValueError):  # called outside a Dask worker
        return None


def _over_stop_budget(exc):
    if exc is None:
        return False
    from fpga_robotics.sim.pins.base import StopLimit  # lazy: loaded by any run that raises it

    return isinstance(exc, StopLimit)


def set_stop_limit(design, limit):
    """Give a run's design its stop budget (``limit`` watched changes, None: none). A
    frame-level design has none: its frames' cycle watchdog bounds its work."""
    if hasattr(design, "stop_limit"):
        design.stop_limit = limit


def stops_of(design):
    """The watched changes a pin-level design stopped at in its last run (None: a frame-level
    design)."""
    return getattr(design, "stops", None)


class RunOutcome:
    """How every campaign task records one run, as a context manager: ``out`` is the
    outcome dict (``status``: the summary's verdict, ``"timeout"`` or ``"error"`` with the
    exception's first line in ``message``; ``summary``; ``run_s``, ``wall_s``, ``cpu_s``).
    An exception in the body becomes the outcome (the campaign records it and goes on);
    ``deadline``, once set, is cancelled at the end."""

    def __init__(self):
        self._wall0, self._cpu0 = time.perf_counter(), time.process_time()
        self.out = {"status": "error", "message": "", "summary": None, "recording": None}
        self.out["run_s"] = 0.0
        self.deadline = None

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if isinstance(exc, RunTimeout) or _over_stop_budget(exc):
            self.out.update(status="timeout", message=str(exc))
        elif isinstance(exc, Exception):
            self.out.update(status="error", message=f"{type(exc).__name__}: {exc}".splitlines()[0])
            if isinstance(exc, UsageError):  # the run's own arguments or files: not the design's
                self.out["usage_error"] = True
        if self.deadline is not None:
            self.deadline.cancel()
        self.out["wall_s"] = time.perf_counter() - self._wall0
        self.out["cpu_s"] = time.process_time() - self._cpu0
        return isinstance(exc, Exception)  # never KeyboardInterrupt or SystemExit

    @contextlib.contextmanager
    def running(self):
        """Times the run itself (``run_s``), whether it ends or raises."""
        t_run = time.perf_counter()
        try:
            yield
        finally:
            self.out["run_s"] = time.perf_counter() - t_run

    def record(self, result):
        """The run's ``RunResult``: its summary and verdict."""
        summary = dict(result.summary)
        self.out.update(status=summary["verdict"], summary=summary)


def execute(argv, timeout=None, record=False, tag=None, bag=False, stop_limit=None):
    """Run one campaign run (``tag``: its name, for the timeout event; ``record``: False, or
    log every how many frames' images to the recording); returns ``{"status", "message",
    "summary", "wall_s", "cpu_s", "run_s", "recording", "bag", "design_stops"}``
    (``recording``: the ``.rrd`` bytes when ``record``; ``bag``: with ``bag`` and ``record``,
    the ROS 2 bag's files as ``{name: bytes}``; ``design_stops``: ``stops_of`` the design).
    ``stop_limit``: a pin-level design's stop budget (``set_stop_limit``); over it the run
    is a ``timeout``, wherever it is run."""
    from fpga_robotics.cli import run  # lazy: the run stack (~1 s)
    from fpga_robotics.loop.timings import run_scenario  # lazy: the run stack (~1 s)

    with RunOutcome() as outcome:
        out = outcome.out
        args, scenario, shadow_params = _loaded(argv)
        design, shadow = _designs_for(args, scenario, shadow_params)
        if getattr(args, "runtime", None):  # a kept design gets this run's [runtime] values
            run.apply_runtime(design, args)
        set_stop_limit(design, stop_limit)  # a kept design: this run's, or none
        outcome.deadline = deadline = _Deadline(timeout, _fault(args), tag)
        recorder, rrd = (None, None)
        if record:
            recorder, rrd = _recorder(args, scenario.name, int(record))
        bag_writer, bag_dir = _bag_writer(scenario) if record and bag else (None, None)
        try:
            with outcome.running():
                result = run_scenario(
                    scenario,
                    seed=args.seed,
                    backend=design,
                    recorder=recorder,
                    progress=deadline,
                    realtime=False,
                    shadow=shadow,
                    shadow_label=args.shadow or "shadow",
                    on_frame=bag_writer.log_frame if bag_writer else None,
                )
                if bag_writer is not None:
                    bag_writer.close()
                    out["bag"] = _read_bag(bag_dir)
        finally:
            out["design_stops"] = stops_of(design)
            if recorder is not None:
                run._close_recorder(recorder, True)
            if bag_writer is not None:
                bag_writer.abandon()  # nothing left once closed; a partial bag otherwise
                shutil.rmtree(bag_dir, ignore_errors=True)
        if rrd is not None:
            out["recording"] = rrd.read_bytes()
            rrd.unlink(missing_ok=True)
        outcome.record(result)
    return outcome.out


def _bag_writer(scenario):
    """A ROS 2 bag writer into a temporary folder (``fpga_robotics.ros``), and the folder."""
    from ..ros.bag_writer import open_bag_writer  # lazy: the run stack (~1 s)

    folder = Path(tempfile.mkdtemp(prefix="sweep-bag-"))
    return open_bag_writer(folder / "bag", scenario), folder


def _read_bag(folder):
    """The files of the bag written into ``folder`` as ``{name: bytes}``."""
    bag = folder / "bag"
    return {p.name: p.read_bytes() for p in sorted(bag.iterdir()) if p.is_file()}


def _recorder(args, name, log_every):
    from fpga_robotics.cli import run  # lazy: the run stack (~1 s)

    fd, path = tempfile.mkstemp(prefix=f"sweep-{name}-", suffix=".rrd")
    os.close(fd)
    args.rerun = f"save:{path}"
    args.log_every = log_every
    return run._open_recorder(args, name), Path(path)
