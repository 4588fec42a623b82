"""The robot judge: each mutant against a campaign's closed-loop verdicts.

First the campaign's runs go with the unmutated design (the mutant netlist at ``mutsel = 0``):
the runs that pass are the judging runs. A mutant is *caught* when any judging run does not
pass with it (fails, errs or times out). A mutant's runs go in the campaign's order and stop
at the first that does not pass (most caught mutants fail their first run), one Dask task per
mutant on the campaign engine's workers (``fpga_robotics.sweep``): each worker keeps the
compiled model loaded and switches ``mutsel`` between runs.

Every run is a ``python -m fpga_robotics.run`` argument list (the campaign's, with
``--design verilog:mutants.v --ports mutants_ports.toml --runtime mutsel=K`` and the mutant
design's resolution), so each verdict comes with the command that replays it.
"""

import hashlib
import json
import os
import shlex
import shutil
import threading
import time
import tomllib
from dataclasses import fields, replace
from itertools import pairwise

from fpga_robotics.checks.registry import CHECKS, check_named
from fpga_robotics.hw.errors import UsageError
from fpga_robotics.hw.params import FollowTargetParams

from ..hw.verilog import TOP_NAME
from ..scenario.load import parse_resolution
from ..sim.files import write_atomic
from ..sweep import runner
from ..sweep.api import wait_for_a_worker
from ..sweep.campaign import toml_value
from ..sweep.engine import open_client
from ..sweep.plan import make_plan
from .cone import cone_verdict, settled_by_cone
from .forked_runs import execute_forked, outcome_of, reference_share
from .same_verdicts import journal_rows

__all__ = [
    "JOURNAL_NAME",
    "campaign_runs_key",
    "check_campaign",
    "check_design_params",
    "check_design_values",
    "check_resume",
    "clear_earlier_run",
    "closest_to_failing",
    "design_sets",
    "judge_runs",
    "judge_runs_forked",
    "mutant_argv",
    "mutants_key",
    "replay",
    "robot_judge",
    "run_limits",
    "run_margin",
    "start_prebuild",
]


#: The robot judge's journal in the output folder (what ``--resume`` keeps).
JOURNAL_NAME = "robot.jsonl"
#: What a run leaves in its output folder beside the netlist, its port maps and the journal.
_RESULTS = ("mutants.json", "report.html", "recordings")


def clear_earlier_run(out_dir, resume=False):
    """Remove an earlier run's results from ``out_dir`` before this run writes its netlist
    there, so that a run that fails or is interrupted leaves none of them beside the new
    netlist (whose mutants they do not describe); the journal too unless ``resume`` (checked
    by ``check_resume`` to hold this run's verdicts)."""
    for name in (*_RESULTS, *(() if resume else (JOURNAL_NAME,))):
        path = os.path.join(out_dir, name)
        if os.path.isdir(path):
            shutil.rmtree(path)
        elif os.path.exists(path):
            os.remove(path)


def _asked_resolutions(spec):
    """The camera resolutions a campaign run asks for itself, as (width, height): its
    ``resolution`` and its ``camera.resolution`` sets (values as ``run --set`` reads them)."""
    asked = [spec.resolution] if spec.resolution is not None else []
    asked += [value for key, value in spec.overrides if key == "camera.resolution"]
    for item in spec.fixed:
        key, _, text = item.partition("=")
        if key.strip() == "camera.resolution":
            try:
                asked.append(tomllib.loads(f"v = {text}")["v"])
            except tomllib.TOMLDecodeError:
                asked.append(text.strip())
    return [parse_resolution(value) for value in asked]


def check_campaign(campaign, resolution=None):
    """``campaign``'s plan (``sweep.plan.make_plan``: every run's scenario and overrides
    loaded), or ``UsageError`` for what a mutation campaign may not hold: its runs take the
    mutant netlist as their design, on Verilator, so no ``design``, ``ports`` or
    ``design.*`` values of its own and no other backend; with ``resolution`` ("WxH": the
    frame size the netlist is built for, which every run takes) no other resolution. Call
    it before anything is built or written."""
    runs = campaign.runs
    for key, what in (("design", "design = ..."), ("ports", "ports = ...")):
        if any(getattr(spec, key) is not None for spec in runs):
            raise UsageError(
                f"the mutation campaign may not give {what}: its runs take the mutant "
                "netlist as their design (the mutants are of one design)"
            )
    other = sorted({spec.backend for spec in runs} - {"auto", "verilator"})
    if other:
        raise UsageError(
            f"the mutation campaign's backend {other[0]!r}: the mutant netlist runs on "
            'Verilator (backend = "auto" or "verilator")'
        )
    if any(k.startswith("design.") for spec in runs for k, _ in spec.overrides) or any(
        item.startswith("design.") for spec in runs for item in spec.fixed
    ):
        raise UsageError(
            "the mutation campaign may not override design.* values: the "
            "mutants are of one design (give its parameters to mutate instead)"
        )
    plan = make_plan(campaign)
    if resolution is not None:  # read after make_plan has checked every run's values
        built_for = parse_resolution(resolution)
        for spec in runs:
            other = next((r for r in _asked_resolutions(spec) if r != built_for), None)
            if other is not None:
                raise UsageError(
                    f"the mutation campaign asks for resolution {other[0]}x{other[1]} "
                    f"({spec.scenario}): the mutant netlist is built for {resolution}, which "
                    "every run takes (give the frame size to mutate instead: --width, --height)"
                )
    return plan


def check_design_bindings(plan, design_argv):
    """``UsageError`` when a run of the campaign (``plan``: ``check_campaign``'s) cannot
    drive the design ``design_argv`` names (``--design REF`` and its ``--ports``): its
    scenario's sensors against the design's pins, checked as ``run`` checks them before a
    model is built, so before the mutants are."""
    from ..loop.bindings import check_bindings  # lazy: the run stack (~1 s)

    seen = set()
    for spec in plan.runs:
        argv = [*spec.argv(), *design_argv]
        if tuple(argv) in seen:
            continue
        seen.add(tuple(argv))
        try:
            _, scenario, _ = runner.load_run(argv)
            check_bindings(scenario)
        except UsageError as exc:
            raise UsageError(f"the campaign's run of {spec.scenario}: {exc}") from None


def _refuse_usage_errors(argvs, outcomes):
    """A run of the unmutated design that ended in a usage error (its scenario cannot run the
    design at all, as ``run`` would say with exit 2): the campaign is the user's to fix, not
    a run to judge without."""
    for argv, outcome in zip(argvs, outcomes, strict=True):
        if outcome.get("usage_error"):
            scenario = argv[argv.index("--scenario") + 1]
            message = outcome["message"].removeprefix("UsageError: ")
            raise UsageError(f"the campaign's run of {scenario}: {message}")


def start_prebuild(campaign, netlist, ports, resolution, design=()):
    """Build, in a thread of this process, the model the robot judge's unmutated runs open
    (``netlist`` with ``ports``, its watch map: a model of its own), while the unit judge
    runs; returns the thread, for ``robot_judge(prebuilt=...)`` to wait for. A build that
    fails here fails again, with its message, in the run that needs it."""

    def build():
        for spec in make_plan(campaign).runs:
            try:
                runner.build_designs(
                    mutant_argv(spec.argv(), netlist, ports, 0, resolution, design)
                )
            except Exception:  # noqa: BLE001 - the run reports it
                return

    thread = threading.Thread(target=build, name="prebuild", daemon=True)
    thread.start()
    return thread


def mutants_key(design, mutants):
    """What names a set of mutants: ``design`` (text that names the unmutated design, its
    parameters or its source) and each mutant's Yosys command, in order. A journal row
    carries it, so ``--resume`` keeps only verdicts of these very mutants."""
    text = "\n".join([design, *(m.command for m in mutants)])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def campaign_runs_key(plan):
    """What names the runs that judge the mutants: each run's identity in ``plan`` (sweep's
    ``run_identity``: the scenario's content, seed, duration, overrides, checks), in order. A
    journal row carries it, so ``--resume`` keeps only verdicts of these very runs."""
    text = "\n".join(plan.ids[spec] for spec in plan.runs)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def check_resume(out_dir, key, campaign):
    """``UsageError`` if ``out_dir``'s journal holds verdicts of other mutants than ``key``
    names (another design, seed or ``--mutants``) or verdicts judged by other runs than
    ``campaign``'s: call it before writing anything there."""
    journal = os.path.join(out_dir, JOURNAL_NAME)
    if not os.path.exists(journal):
        return
    rows = journal_rows(journal)
    if {row.get("mutants") for row in rows} - {key}:
        raise UsageError(
            f"--resume: {journal} holds verdicts of other mutants (another design, --seed "
            "or --mutants): give the same ones, or drop --resume to judge these afresh"
        )
    runs = campaign_runs_key(check_campaign(campaign))
    if {row.get("campaign_runs") for row in rows} - {runs}:
        raise UsageError(
            f"--resume: {journal} holds verdicts judged by other runs than campaign "
            f"{campaign.name}'s (another campaign, or its scenarios, seeds, duration, checks "
            "or overrides since changed): give the same campaign, or drop --resume to judge "
            "these afresh"
        )


def design_sets(params):
    """The ``--set design.NAME=VALUE`` items that give a run FollowTarget's ``params``: those
    that differ from the defaults at its frame size. A run of the mutant netlist is judged by
    its scenario's design values (the behaviour envelopes' laws, the stop distance): with
    these they are the values the netlist was built with."""
    default = FollowTargetParams(width=params.width, height=params.height)
    return [
        f"design.{f.name}={toml_value(getattr(params, f.name))}"
        for f in fields(FollowTargetParams)
        if f.init
        and f.name not in ("width", "height")
        and getattr(params, f.name) != getattr(default, f.name)
    ]


def check_design_values(plan, params):
    """``UsageError`` when a run of ``plan`` (``check_campaign``'s) has design values of its
    own, in its scenario's ``[design]``, other than those FollowTarget's mutants are built
    with (``params``, which ``design_sets`` gives every run). Call it before anything is
    built."""
    resolution = f"{params.width}x{params.height}"
    default = FollowTargetParams(width=params.width, height=params.height)
    seen = set()
    for spec in plan.runs:
        shape = replace(spec, seed=0)
        if shape in seen:
            continue
        seen.add(shape)
        argv = _with_netlist_values(spec.argv(), resolution)
        own = runner.load_run([*argv, "--design", "follow_target"])[1].params
        differ = [
            f.name
            for f in fields(FollowTargetParams)
            if f.init
            and getattr(own, f.name) not in (getattr(default, f.name), getattr(params, f.name))
        ]
        if differ:
            theirs, ours = (
                ", ".join(f"{n} = {toml_value(getattr(p, n))}" for n in differ)
                for p in (own, params)
            )
            raise UsageError(
                f"the campaign's run of {spec.scenario}: its scenario's design values "
                f"({theirs}) are not the mutated design's ({ours}): the mutants are of one "
                "design (give its parameters to mutate instead)"
            )


def check_design_params(plan, design_argv, spec):
    """``UsageError`` when a run of ``plan`` (``check_campaign``'s) gives the design of
    one's own that ``design_argv`` names (``--design REF``) other ``[design.params]`` than
    the mutants are built with (``spec``, its ``DesignSpec`` with ``--param``): the mutant
    netlist takes none, so the run would judge another design than its scenario asks for.
    Compared by elaborated netlist, so a value given as its default is the same design.
    Call it before anything is built."""
    from ..designs.reference import resolve_design  # lazy: Amaranth (~0.5 s)

    seen = set()
    for run in plan.runs:
        shape = replace(run, seed=0)
        if shape in seen:
            continue
        seen.add(shape)
        scenario = runner.load_run([*run.argv(), *design_argv])[1]
        theirs = scenario.design_params
        if resolve_design(scenario.top, theirs).netlist_digest != spec.netlist_digest:
            name = spec.reference.rpartition(":")[2]
            ours = ", ".join(f"{k} = {toml_value(v)}" for k, v in spec.params.items())
            given = ", ".join(f"{k} = {toml_value(v)}" for k, v in theirs.items())
            raise UsageError(
                f"the campaign's run of {run.scenario}: its [design.params] ({given or 'none'})"
                f" make another {name} than the one mutated ({ours or 'no --param'}; a parameter"
                " not given takes its default): the mutants are of one design (give its "
                "parameters to mutate as --param NAME=VALUE)"
            )


def _with_netlist_values(argv, resolution, design=()):
    """A campaign run's arguments without a design and backend of their own, at
    ``resolution`` (None: the run's own) and with ``design``, ``design_sets`` items."""
    replaced = ("--backend", "--design", "--ports", "--runtime")
    if resolution is not None:
        replaced += ("--resolution",)
    out, skip = [], False
    for a in argv:
        if skip:
            skip = False
            continue
        if a in replaced:
            skip = True
            continue
        out.append(a)
    # A run's own camera.resolution set is the netlist's (check_campaign): run refuses
    # --resolution beside it.
    sets_it = any(
        a == "--set" and b.partition("=")[0].strip() == "camera.resolution"
        for a, b in pairwise(out)
    )
    return [
        *out,
        *(("--resolution", resolution) if resolution is not None and not sets_it else ()),
        *(x for item in design for x in ("--set", item)),
    ]


def mutant_argv(argv, netlist, ports, index, resolution, design=()):
    """A campaign run's arguments with mutant ``index`` of the netlist as the design (at
    ``resolution``; when None, a design of one's own, at the run's: the campaign's or its
    scenario's), FollowTarget's with its parameters (``design``: ``design_sets``)."""
    return [
        *_with_netlist_values(argv, resolution, design),
        "--backend",
        "verilator",
        "--design",
        f"verilog:{netlist}",
        "--ports",
        str(ports),
        "--runtime",
        f"mutsel={index}",
    ]


def replay(argv):
    """The shell command that replays a run."""
    return shlex.join(["python", "-m", "fpga_robotics.run", *argv])


def run_margin(summary):
    """How far a passing run is from failing: the smallest relative margin of its measured
    checks (value against limit, 0 = on the limit; None when no check has a number)."""
    margins = []
    for c in summary.get("checks", ()):
        v, limit = c.get("value"), c.get("limit")
        if (
            c.get("passed") is None
            or isinstance(v, bool)
            or not isinstance(v, (int, float))
            or not isinstance(limit, (int, float))
            or c.get("name") not in CHECKS  # which way it fails is unknown here
        ):
            continue
        scale = max(abs(float(limit)), 1e-9)
        if check_named(c["name"]).compare == "min":  # the value must be at least the limit
            margins.append((float(v) - float(limit)) / scale)
        else:
            margins.append((float(limit) - float(v)) / scale)
    return min(margins) if margins else None


def closest_to_failing(outcomes):
    """The index of the passing outcome with the smallest ``run_margin`` (None if none)."""
    best, best_margin = None, None
    for i, o in enumerate(outcomes):
        if o.get("status") != "pass" or not o.get("summary"):
            continue
        m = run_margin(o["summary"])
        if m is not None and (best_margin is None or m < best_margin):
            best, best_margin = i, m
    return best


def run_limits(outcome):
    """A mutant's limits for a run whose unmutated outcome is ``outcome``: ``(seconds,
    stops)``. ``stops``, the budget that decides a ``timeout``, counts the design's own work,
    so the verdict is the same on any machine: a hundred times the watched output changes
    the unmutated design stopped at, plus a million (None for a frame-level design, whose
    frames' cycle watchdog bounds its work). A mutant that only triggers a sensor far more
    often runs to its end and is judged by its checks; one that changes a watched output at
    nearly every edge of a fast clock does not end in reasonable time. ``seconds`` only
    catches a run that hangs outside the design's cycles: 30 times the unmutated run's, at
    least 120 s."""
    stops = outcome.get("design_stops")
    return (
        max(120.0, 30.0 * outcome.get("wall_s", 3.0)),
        None if stops is None else 100 * stops + 1_000_000,
    )


def _failed_checks(outcome):
    """The names of a run's failed checks (none without a summary)."""
    checks = (outcome.get("summary") or {}).get("checks", ())
    return [c["name"] for c in checks if c.get("passed") is False]


def _run_message(outcome):
    """A run's error or timeout as its user reads it: without the class name of a usage
    error (its text is the user's already) and without the ``--design: follow_target: `` that
    names the mutant netlist's generated top, which every run of the robot judge runs."""
    message = (outcome.get("message") or "").removeprefix("UsageError: ")
    return message.removeprefix(f"--design: {TOP_NAME}: ")


def _why_not_passed(outcome):
    """Why a run did not pass: its error or timeout, else its failed checks ("" if none)."""
    failed = _failed_checks(outcome)
    return _run_message(outcome) or (f"failed checks: {', '.join(failed)}" if failed else "")


def judge_runs(argvs, limits=None, execute=None):
    """The Dask task of one mutant: its runs in order until one does not pass. Returns
    ``{"caught", "run", "status", "message", "failed_checks", "closest", "runs", "wall_s"}``
    (``run``: the index of the first run that did not pass; ``closest``: of a mutant not
    caught, the run nearest to failing), and ``"forks"`` for forked runs: their
    ``forked_runs.execute_forked`` records, in order. ``limits``: each run's ``(seconds,
    stops)`` (``run_limits``; None: no limits). ``execute(i, argv, limit)`` runs run ``i``
    (default ``runner.execute``; forked runs: fpga_robotics.mutation.forked_runs)."""
    if execute is None:

        def execute(i, argv, limit):
            seconds, stops = limit
            return runner.execute(argv, timeout=seconds, stop_limit=stops)

    t0 = time.perf_counter()
    outcomes = []
    forks = []  # each forked run's "fork" record (forked_runs.execute_forked)
    for i, argv in enumerate(argvs):
        o = execute(i, argv, (None, None) if limits is None else limits[i])
        o.pop("recording", None)
        outcomes.append(o)
        if o.get("fork") is not None:
            forks.append(o["fork"])
        if o["status"] != "pass":
            return {
                "caught": True,
                "run": i,
                "status": o["status"],
                "message": _run_message(o),
                "failed_checks": _failed_checks(o),
                "closest": None,
                "runs": i + 1,
                "wall_s": time.perf_counter() - t0,
                **({"forks": forks} if forks else {}),
            }
    return {
        "caught": False,
        "run": None,
        "status": "pass",
        "message": "",
        "failed_checks": [],
        "closest": closest_to_failing(outcomes),
        "runs": len(argvs),
        "wall_s": time.perf_counter() - t0,
        **({"forks": forks} if forks else {}),
    }


def _baseline(client, argvs, progress, fork, timeout=None):
    """The campaign with the unmutated design: ``([outcome] in order, shared)``, each run
    limited to ``timeout`` seconds (the campaign file's). With ``fork``, ``shared`` are the
    futures of the runs' ``reference_share`` results, kept in the cluster for the mutants'
    tasks (each reference run once); else None."""
    from distributed import as_completed  # lazy: Dask costs ~1 s; only a run needs it

    shared = None
    if fork:
        shared = [client.submit(reference_share, a, timeout, pure=False) for a in argvs]
        # The outcomes come on their own: the references stay on the workers.
        futures = {client.submit(outcome_of, s, pure=False): i for i, s in enumerate(shared)}
    else:
        futures = {
            client.submit(runner.execute, a, timeout, pure=False): i for i, a in enumerate(argvs)
        }
    out = [None] * len(argvs)
    for fut in as_completed(futures):
        try:
            out[futures[fut]] = fut.result()
        except Exception as exc:  # noqa: BLE001 (its worker ended it: a frame hung past the timeout)
            message = f"{type(exc).__name__}: {exc}".splitlines()[0]
            out[futures[fut]] = {"status": "error", "message": message, "summary": None}
        progress(1)
    return out, shared


def robot_judge(
    campaign,
    netlist,
    ports,
    resolution,
    indices,
    out_dir,
    *,
    workers=None,
    scheduler=None,
    resume=False,
    progress=None,
    say=print,
    fork=True,
    cones=None,
    watch_ports=None,
    mutants=None,
    prebuilt=None,
    design=(),
):
    """Judge the mutants ``indices`` by ``campaign``'s closed-loop runs.

    Returns ``(baseline, verdicts)``: ``baseline`` is ``{"runs": [argv at mutsel 0, ...],
    "passing": [their indices], "statuses": [...], "messages": [why each did not pass, or
    ""], "judged_here": how many mutants this call judged, "kept": the indices of the others,
    kept from the journal}``; ``verdicts`` is ``{index: judge_runs result}`` (with the replay command of
    the run that caught it, or of the closest run; empty when no run passes unmutated).
    Verdicts are appended to ``out_dir/robot.jsonl`` as they come (``resume`` keeps the
    ones there). With ``fork`` each mutant's run is forked from the unmutated design's
    (fpga_robotics.mutation.forked_runs): the same verdicts, most of the world not
    re-simulated; and a mutant whose fan-out cone (``cones``: ``{index: reach}``, from
    ``sim.mutation.mutant_cones``) reaches no output the runs read gets its verdict without
    a run (fpga_robotics.mutation.cone). ``watch_ports``: the netlist's port map with its
    watch output watched (``design.write_mutant_design``); with ``fork`` the unmutated runs
    use it, and a mutant that never acted in one of them is given it without a run.
    ``mutants``: their ``mutants_key``, in every journal row with the ``campaign_runs_key``
    (``resume`` keeps only rows of the same mutants and runs, and of ``indices``: the journal
    is written again with those alone; ``check_resume`` refuses others before anything is
    written). ``prebuilt``: the ``start_prebuild`` thread to wait for
    before the runs. ``design``: FollowTarget's parameters for every run (``design_sets``)."""
    from distributed import as_completed  # lazy: Dask costs ~1 s; only a run needs it

    tick = progress or (lambda n: None)
    plan = check_campaign(campaign)
    runs_key = campaign_runs_key(plan)
    watch_ports = watch_ports if fork else None
    base = [
        mutant_argv(spec.argv(), netlist, watch_ports or ports, 0, resolution, design)
        for spec in plan.runs
    ]
    journal = os.path.join(out_dir, JOURNAL_NAME)
    verdicts = {}
    if resume and os.path.exists(journal):
        # Only the mutants judged now: one the unit judge no longer catches (other --cycles,
        # --against, ...) has no robot verdict in this run's scores.
        wanted = set(indices)
        for row in journal_rows(journal):
            same = (row.get("mutants"), row.get("campaign_runs")) == (mutants, runs_key)
            if same and int(row["index"]) in wanted:
                verdicts[int(row["index"])] = row
        # Written again whole: a torn last line would swallow the first row appended to it.
        write_atomic(
            journal, "".join(json.dumps(v) + "\n" for v in verdicts.values()), what="journal"
        )
    elif os.path.exists(journal):
        os.remove(journal)
    if prebuilt is not None:
        prebuilt.join()
    with open_client(scheduler=scheduler, workers=workers) as client:
        wait_for_a_worker(client, scheduler)
        say(f"robot judge: {len(base)} campaign runs with the unmutated design first")
        outcomes, shared = _baseline(client, base, tick, fork, campaign.timeout)
        _refuse_usage_errors(base, outcomes)
        passing = [i for i, o in enumerate(outcomes) if o["status"] == "pass"]
        statuses = [o["status"] for o in outcomes]
        messages = [_why_not_passed(o) for o in outcomes]
        if not passing:  # nothing to judge by: no verdict, rather than a pass of no run
            say(f"robot judge: no run of the {len(base)} passes with the unmutated design")
            return (
                {
                    "runs": base,
                    "passing": [],
                    "statuses": statuses,
                    "messages": messages,
                    "judged_here": 0,
                    "kept": [],
                },
                {},
            )
        limits = [run_limits(outcomes[i]) for i in passing]
        todo = [k for k in indices if k not in verdicts]
        say(
            f"robot judge: {len(passing)} of {len(base)} runs pass unmutated; judging "
            f"{len(todo)} mutants ({len(indices) - len(todo)} already in {journal})"
        )
        # A fault no run can see passes every run as the design does: no run made.
        settled = (
            settled_by_cone(cones, ports, [base[i] for i in passing]) if fork and cones else {}
        )
        settled = {k: settled[k] for k in todo if k in settled}
        closest = closest_to_failing([outcomes[i] for i in passing])
        if settled:
            n = len(settled)
            say(f"robot judge: {n} mutant{'s' * (n != 1)} settled by the fan-out cone, no run")
        futures = {}
        for k in (k for k in todo if k not in settled):
            argvs = [
                mutant_argv(spec.argv(), netlist, ports, k, resolution, design)
                for spec in (plan.runs[i] for i in passing)
            ]
            if fork:
                refs = [shared[i] for i in passing]  # Dask hands each worker their results
                bit = k - 1 if watch_ports else None  # sim.mutant_watch
                task = (judge_runs_forked, argvs, [base[i] for i in passing], limits, refs, bit)
            else:
                task = (judge_runs, argvs, limits)
            futures[client.submit(*task, pure=False, key=f"mutant-{k}-{time.monotonic_ns()}")] = (
                k,
                argvs,
            )
        with open(journal, "a") as f:
            for k, reached in settled.items():
                v = cone_verdict(reached, closest)
                at = plan.runs[passing[closest]].argv() if closest is not None else None
                v["argv"] = at and mutant_argv(at, netlist, ports, k, resolution, design)
                v["replay"] = replay(v["argv"]) if at else None
                v["index"], v["mutants"], v["campaign_runs"] = k, mutants, runs_key
                verdicts[k] = v
                f.write(json.dumps(v) + "\n")
                tick(1)
            for fut in as_completed(futures):
                k, argvs = futures[fut]
                try:
                    v = fut.result()
                except Exception as exc:  # noqa: BLE001 (a worker died: the mutant is caught)
                    v = {
                        "caught": True,
                        "run": None,
                        "status": "error",
                        "message": f"{type(exc).__name__}: {exc}".splitlines()[0],
                        "failed_checks": [],
                        "closest": None,
                        "runs": 0,
                        "wall_s": 0.0,
                    }
                at = v["run"] if v["caught"] else v["closest"]
                v["argv"] = argvs[at] if at is not None else None
                v["replay"] = replay(v["argv"]) if at is not None else None
                v["index"], v["mutants"], v["campaign_runs"] = k, mutants, runs_key
                verdicts[k] = v
                f.write(json.dumps(v) + "\n")
                f.flush()
                tick(1)
    return (
        {
            "runs": base,
            "passing": passing,
            "statuses": statuses,
            "messages": messages,
            "judged_here": len(todo),
            "kept": sorted(set(indices) - set(todo)),
        },
        verdicts,
    )


def judge_runs_forked(argvs, ref_argvs, limits=None, shared=None, watch_bit=None):
    """``judge_runs`` with each run forked from its reference run (``forked_runs``);
    ``shared``: the reference runs' ``reference_share`` results (None: each worker runs
    them itself); ``watch_bit``: the mutant's bit of the references' watch output."""
    return judge_runs(
        argvs,
        limits,
        execute=lambda i, argv, limit: execute_forked(
            argv,
            ref_argvs[i],
            limit[0],
            None if shared is None else shared[i],
            watch_bit,
            stop_limit=limit[1],
        ),
    )
