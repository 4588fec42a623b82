"""``fpga-robotics mutate``: how many gateware bugs do the unit frames catch?

Generates N mutants of ``FollowTarget`` with Yosys's ``mutate`` pass (seeded), builds one
Verilator model holding all of them (``mutsel`` picks one), runs each through the unit judge
(every output against the golden model on fixed frames), and writes ``mutants.json`` into
the output folder; the terminal gets the score, the score per component and the mutants no
frame shows.
"""

import argparse
import contextlib
import os
import shutil
import sys
import time

from fpga_robotics.cli.errors import UsageError
from fpga_robotics.cli.param_options import (
    add_define_argument,
    add_design_param_argument,
    add_param_arguments,
    defines_from_items,
    design_params_from_items,
    params_from_args,
    refuse_followtarget_options,
)
from fpga_robotics.cli.parser import CommandParser
from fpga_robotics.designs.reference import resolve_design
from fpga_robotics.mutation.design import (
    WATCH_PORTS_NAME,
    open_mutant_design,
    write_mutant_design,
)
from fpga_robotics.mutation.design_run import (
    DEFAULT_CYCLES,
    DEFAULT_FRAME,
    mutate_design,
    mutate_verilog_design,
)
from fpga_robotics.mutation.reasons import blind_spot_reason
from fpga_robotics.mutation.report import write_report
from fpga_robotics.mutation.robot_judge import (
    JOURNAL_NAME,
    check_campaign,
    check_design_bindings,
    check_design_params,
    check_design_values,
    check_resume,
    clear_earlier_run,
    design_sets,
    mutants_key,
    robot_judge,
    start_prebuild,
)
from fpga_robotics.mutation.same_verdicts import journal_rows
from fpga_robotics.mutation.scores import blind_spots, by_module, robot_score, unit_score
from fpga_robotics.mutation.unit_judge import (
    golden_results,
    judge_frames,
    judge_mutant,
    reference_results,
)
from fpga_robotics.sim.backends.base import BackendError
from fpga_robotics.sim.backends.port_map import PortMapError
from fpga_robotics.sim.backends.verilog_params import VerilogOverrides
from fpga_robotics.sim.files import check_output_dir, write_atomic, write_json_atomic
from fpga_robotics.sim.mutation import MAX_MUTANT_SEED, MutationError, list_mutants, mutant_cones
from fpga_robotics.sim.pins import PinError
from fpga_robotics.sweep import load_campaign_file, runner
from fpga_robotics.sweep.engine import check_cluster_options, open_client

__all__ = ["main"]


def _campaign(name, params):
    """The campaign ``name`` with every run checked (``check_campaign``, with the mutant
    netlist's resolution and design values ``params``): a typo fails here, before anything
    is built or written."""
    campaign = load_campaign_file(name)
    plan = check_campaign(campaign, f"{params.width}x{params.height}")
    # Its scenarios' sensors against FollowTarget's pins too: a campaign of another design
    # (sensor_designs) fails here, not after the build and the unit judge.
    check_design_bindings(plan, ["--design", "follow_target"])
    check_design_values(plan, params)
    return campaign


def _exit_code(baseline):
    """1 when a campaign was given and none of its runs passes unmutated (no robot judge),
    else 0."""
    return 1 if baseline is not None and not baseline["passing"] else 0


def _print_modules(modules, robot_judged):
    """A line per module: its unit score and, where the robot judge ran, its robot score."""
    width = max(len(name) for name in modules)
    for name, row in modules.items():
        robot_part = (
            f", robot judge {row['robot_caught']:>4}/{row['unit_caught']}" if robot_judged else ""
        )
        print(f"  {name:<{width}}  {row['unit_caught']:>4}/{row['total']:<4} caught{robot_part}")


def _no_run_passes(baseline):
    """With no campaign run passing unmutated: say so, and why the first ones did not pass
    (True); else False."""
    if baseline["passing"]:
        return False
    print("no run passes with the unmutated design: the robot judge has no run to judge by")
    shown = 3
    for argv, status, message in list(
        zip(baseline["runs"], baseline["statuses"], baseline["messages"], strict=True)
    )[:shown]:
        scenario = argv[argv.index("--scenario") + 1]
        print(f"  --scenario {scenario}: {status}" + (f": {message}" if message else ""))
    if len(baseline["runs"]) > shown:
        print(f"  ... and {len(baseline['runs']) - shown} more")
    return True


def _report_robot(out, results, robot_s, recordings, say, *, title, inputs):
    """The robot judge's lines, the recordings of the closest runs of the first
    ``recordings`` blind spots, and report.html (``results``: mutants.json's content;
    ``title`` and ``inputs`` as ``write_report`` takes them)."""
    rs, baseline = results["robot"], results["baseline"]
    robot_verdicts = {m["index"]: m["robot"] for m in results["mutants"] if m["robot"]}
    # How they were judged is this run's: not that of the verdicts --resume kept.
    judged_here = {k: v for k, v in robot_verdicts.items() if k not in baseline["kept"]}
    n_runs, n_pass = len(baseline["runs"]), len(baseline["passing"])
    head = f"robot judge (campaign {results['campaign']}: {n_pass} of {n_runs} runs pass unmutated)"
    if not n_pass:  # no score of no run
        print(f"{head}: no mutant judged")
    else:
        print(
            f"{head}: {rs['caught']} of {rs['judged']} unit-caught mutants caught: score "
            f"{_percent(rs['score'])}; {_robot_rate(baseline, robot_s)}" + _settled(judged_here)
        )
    forked = _fork_line(judged_here)
    if forked:
        print(forked)
    if _no_run_passes(baseline):
        return
    blind = [m for m in results["mutants"] if m["robot"] and not m["robot"]["caught"]]
    recorded = _record_closest(out, [m["robot"] for m in blind[:recordings]], say)
    if blind:
        print(f"blind spots: caught by the unit judge, missed by every run ({len(blind)}):")
    for m in blind:
        v = m["robot"]
        print(f"  {m['describe']}")
        print(f"    unit: {m['unit']['effect']}")
        if m.get("blind_spot_reason"):
            print(f"    why: {m['blind_spot_reason']}")
        if v.get("judged_by") == "cone":
            print(f"    {_cone_note(v)}")
        if v.get("replay"):
            recording = recorded.get(m["index"])
            print(
                f"    closest run: {v['replay']}"
                + (f"  (recording {recording})" if recording else "")
            )
    path = write_report(out, results, recorded, title=title, inputs=inputs)
    print(f"report: {path}")


def _cone_note(verdict):
    """One line on a verdict given by the mutant's fan-out cone."""
    reached = verdict.get("cone_outputs") or ["no output"]
    return f"no run made: its fan-out cone reaches only {', '.join(reached)}"


def _settled(robot_verdicts):
    """``"; N settled by their fan-out cone"`` (or nothing): the verdicts given without a run."""
    n = sum(1 for v in robot_verdicts.values() if v.get("judged_by") == "cone")
    return f"; {n} settled by their fan-out cone (no run)" if n else ""


def _fork_line(robot_verdicts):
    """What forking saved: how many forked runs never parted from the unmutated design's,
    how many of those did not run the mutant at all (its watch bit never rose), and the
    share of frames whose world was simulated again (None without forked runs)."""
    forks = [f for v in robot_verdicts.values() if v for f in v.get("forks", ())]
    if not forks:
        return None
    never = sum(1 for f in forks if f["parted_at"] is None)
    unrun = sum(1 for f in forks if not f["design_ran"])
    frames = sum(f["frames"] for f in forks)
    world = sum(f["frames"] - f["world_from"] for f in forks if f["world_from"] is not None)
    return (
        f"forked runs: {len(forks)}; {never} never parted from the unmutated design's "
        f"({unrun} without running the mutant: it never acted); the world simulated again "
        f"for {world} of {frames} frames ({_percent(world / max(frames, 1))})"
    )


def _robot_rate(baseline, seconds):
    """The robot judge's rate: the mutants it judged in this run (not those ``--resume``
    kept) per minute of its wall time, the baseline runs included."""
    judged_here = baseline["judged_here"]
    if not judged_here:
        return "no mutant judged in this run (all kept by --resume)"
    return f"{60 * judged_here / max(seconds, 1e-9):.0f} mutants/min"


def _record_closest(out, verdicts, say):
    """Record the closest-to-failing run of each verdict; ``{index: path}``."""
    paths = {}
    for v in verdicts:
        if not v.get("argv"):
            continue
        o = runner.execute(v["argv"], record=1)
        if o.get("recording"):
            path = os.path.join(out, "recordings", f"mutant{v['index']}.rrd")
            os.makedirs(os.path.dirname(path), exist_ok=True)
            write_atomic(path, o["recording"], what="recording")
            paths[v["index"]] = os.path.relpath(path, out)
            say(f"recorded the closest run of mutant {v['index']}: {path}")
    return paths


DEFAULT_MUTANTS = 100
MAX_MUTANTS = 4000
MAX_SEED = MAX_MUTANT_SEED


def build_parser(prog="fpga-robotics mutate"):
    p = CommandParser(
        prog=prog,
        description="Mutation coverage: Yosys mutants of the design, one build for all of "
        "them, each judged against the golden model on fixed frames "
        "(docs/mutation.md).",
    )
    p.add_argument(
        "--mutants",
        type=int,
        default=DEFAULT_MUTANTS,
        metavar="N",
        help=f"how many mutants (default {DEFAULT_MUTANTS}, at most {MAX_MUTANTS})",
    )
    p.add_argument(
        "--seed",
        type=int,
        default=1,
        metavar="S",
        help=f"Yosys's choice of mutants (default 1, at most {MAX_SEED}); the same seed, "
        "the same list",
    )
    p.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="output folder (default runs/mutation/n<N>-s<S>/)",
    )
    p.add_argument(
        "--campaign",
        metavar="NAME|PATH",
        help="also judge the mutants the unit judge catches by this campaign's "
        "closed-loop verdicts (the robot judge; e.g. mutation, regression)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="robot judge: Dask worker processes (default: the machine's cores)",
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="robot judge: an existing Dask scheduler (tcp://HOST:8786)",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="robot judge: keep the mutants already judged in the output folder by the "
        "same campaign's runs",
    )
    p.add_argument(
        "--recordings",
        type=int,
        default=None,  # 5 with --campaign; None tells _check it was not given
        metavar="N",
        help="robot judge: record the closest-to-failing run of the first N blind "
        "spots (default 5)",
    )
    p.add_argument(
        "--fork",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="robot judge: fork each mutant's runs from the unmutated design's at "
        "the first frame its wheel commands differ (default; the same "
        "verdicts, docs/mutation.md) or, with --no-fork, run them in full",
    )
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument(
        "--against",
        choices=("model", "design"),
        default=None,
        help="FollowTarget's unit judge compares each mutant with the golden model "
        "(default) or with the unmutated design on the same frames",
    )
    p.add_argument(
        "--design",
        metavar="REF",
        help="mutants of this design (FILE.py:Name, package.module:Name, or "
        "verilog:FILES with --ports; docs/your_design.md) instead of FollowTarget, each "
        "judged against "
        "the unmutated design on seeded random inputs, cycle by cycle",
    )
    p.add_argument(
        "--resolution",
        metavar="WxH",
        help="with --design, a camera design's unit judge streams frames of this size "
        "(default 160x120)",
    )
    add_design_param_argument(p)
    add_define_argument(p)
    p.add_argument(
        "--ports",
        "--port-map",
        dest="ports",
        metavar="PORTS.toml",
        help="with --design verilog:FILES: the design's port map (docs/foreign.md)",
    )
    p.add_argument(
        "--cycles",
        type=int,
        default=None,
        metavar="N",
        help="with --design: cycles of random inputs per mutant (default 100000)",
    )
    add_param_arguments(p)
    return p


def _resolution(text):
    """``WxH`` as (width, height); ``UsageError`` otherwise."""
    w, x, h = text.lower().partition("x")
    if not (x and w.isdigit() and h.isdigit() and 1 <= int(w) <= 4096 and 1 <= int(h) <= 4096):
        raise UsageError(f"--resolution must be WIDTHxHEIGHT such as 160x120, got {text!r}")
    return int(w), int(h)


def _one_line(exc):
    """An error's first line; where it ends in a colon (a tool failed, its output follows),
    with the tool's first error line after it."""
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    if not lines:
        return type(exc).__name__
    if lines[0].endswith(":") and len(lines) > 1:
        detail = next((x for x in lines[1:] if "error" in x.lower()), lines[1])
        return f"{lines[0]} {detail}"
    return lines[0]


@contextlib.contextmanager
def _removed_on_error(out, campaign):
    """Nothing half-written: a folder this command made is removed again when it fails or is
    interrupted before the robot judge has journaled a verdict (a journal is kept for
    --resume, and so is a folder that was there before). Interrupted with verdicts in the
    journal of a robot judge (``campaign``), say how many and how to go on."""
    existed = os.path.exists(out)
    # The highest folder this command makes (runs/ of runs/mutation/n100-s1): its parents
    # made for it go too.
    made = out
    while not existed and os.path.dirname(made) and not os.path.exists(os.path.dirname(made)):
        made = os.path.dirname(made)
    try:
        yield
    except (Exception, KeyboardInterrupt) as exc:
        journal = os.path.join(out, JOURNAL_NAME)
        if not existed and not os.path.exists(journal):
            shutil.rmtree(made, ignore_errors=True)
        elif isinstance(exc, KeyboardInterrupt) and campaign is not None:
            kept = len(journal_rows(journal)) if os.path.exists(journal) else 0
            if kept:
                print(
                    f"interrupted: {kept} robot judge verdict(s) kept in {journal}; "
                    "continue with --resume",
                    file=sys.stderr,
                )
        raise


def _out(args, name):
    """``--out``, else ``runs/mutation/NAME``; an empty ``--out`` is given, and refused by
    ``check_output_dir``, not taken for the default."""
    return args.out if args.out is not None else os.path.join("runs", "mutation", name)


def _reach_scheduler(address):
    """With ``--scheduler``, connect to it once before anything is built: one that cannot be
    reached is refused in seconds, not after the build and the unit judge (its workers may
    still join while they run)."""
    if address is not None:
        with open_client(scheduler=address):
            pass


#: The connector kinds whose pins a run acts on or a check reads: wheels and a servo move
#: the robot, a camera design's results are checked.
_JUDGED_KINDS = ("wheels", "servo", "camera")


def _refuse_unjudgeable(spec, name):
    """``UsageError`` before any build when no run of a campaign can run or judge the design
    ``spec`` (``name``): an input no connector pin binds (nothing in the closed loop drives
    it) or no output a run acts on or checks."""
    bound = {port for pins in spec.bindings.values() for port in pins.values()}
    # A Verilog design's ports are known once built; its port map maps every input.
    for port, (direction, _) in spec.ports.items():
        # A stream's ports (pixels__valid) are bound by the stream's name.
        if direction == "in" and port not in bound and port.split("__")[0] not in bound:
            raise UsageError(
                f"--campaign: no connector pin drives {name}'s input {port!r}, so no run can "
                "run it; bind it to a connector pin (docs/your_design.md), or leave out "
                "--campaign for the unit judge alone"
            )
    if not any(kind in spec.bindings for kind in _JUDGED_KINDS):
        raise UsageError(
            f"--campaign: no run can catch a mutant of {name}: it binds no wheels, servo or "
            "camera, so nothing in a run acts on its outputs and no check reads them; "
            "leave out --campaign for the unit judge alone"
        )


def _main_design(args):
    """``--design REF``: the mutants of a design of one's own against itself."""
    refuse_followtarget_options(
        args, "with --design REF the mutants are judged against the unmutated design"
    )
    verilog = args.design.startswith("verilog:")
    overrides = None
    if verilog:
        try:
            overrides = VerilogOverrides.of(
                design_params_from_items(args.param), defines_from_items(args.define)
            )
        except PortMapError as exc:
            raise UsageError(str(exc)) from None
    elif args.define:
        raise UsageError("--define sets `define macros of a Verilog design (verilog:FILES)")
    if not verilog and args.ports is not None:
        raise UsageError("--ports is the port map of a Verilog design: it goes with verilog:FILES")
    frame = _resolution(args.resolution) if args.resolution is not None else DEFAULT_FRAME
    cycles = DEFAULT_CYCLES if args.cycles is None else args.cycles
    if not 1 <= cycles <= 100_000_000:
        raise UsageError(f"--cycles must be 1..100000000, got {cycles}")
    if verilog:
        # Resolved as a run resolves it: every file there, the port map readable.
        spec = resolve_design(args.design, ports=args.ports)
        files = spec.reference[len("verilog:") :].split(",")
        name = os.path.splitext(os.path.basename(files[0]))[0]
    else:
        spec = resolve_design(args.design, design_params_from_items(args.param), option="--param")
        spec.require_clock()
        spec.require_no_black_boxes()
        spec.require_defined_domains()
        name = spec.reference.rpartition(":")[2]
    if args.resolution is not None and not spec.camera:
        # Its unit judge streams no frames: the option would do nothing.
        raise UsageError(
            f"--resolution sizes the frames of a camera design's unit judge; {name} has no "
            "camera input"
        )
    campaign = None
    if args.campaign is not None:
        _refuse_unjudgeable(spec, name)
        campaign = load_campaign_file(args.campaign)
        design_argv = ["--design", args.design, *(["--ports", args.ports] if verilog else [])]
        plan = check_campaign(campaign)
        check_design_bindings(plan, design_argv)
        if not verilog:  # a Verilog design takes no parameters
            check_design_params(plan, design_argv, spec)
    out = _out(args, f"{name}-n{args.mutants}-s{args.seed}")
    check_output_dir(out, what="output folder")
    _reach_scheduler(args.scheduler)

    def say(text):
        if not args.quiet:
            print(text, file=sys.stderr, flush=True)

    robot = {
        "workers": args.workers,
        "scheduler": args.scheduler,
        "resume": args.resume,
        "fork": args.fork,
    }
    judged = {"say": say, "campaign": campaign, "robot": robot, "frame": frame}
    try:
        with _removed_on_error(out, campaign):
            if verilog:
                result = mutate_verilog_design(
                    files,
                    args.ports,
                    args.mutants,
                    args.seed,
                    cycles,
                    out,
                    overrides=overrides,
                    **judged,
                )
            else:
                result = mutate_design(spec, args.mutants, args.seed, cycles, out, **judged)
    except (MutationError, BackendError, PinError) as exc:
        raise UsageError(_one_line(exc)) from None
    score, modules = result["unit"], result["modules"]
    print(
        f"{score['total']} mutants of {name} (seed {args.seed}), {cycles} cycles of random "
        f"inputs each; build {result['build_and_list_s']:.1f} s, unit judge "
        f"{result['unit_mutants_per_minute']:.0f} mutants/min"
        + (f", fan-out cones {result['cone_s']:.1f} s" if result.get("cone_s") is not None else "")
    )
    print(
        f"unit judge (against the unmutated design): {score['caught']} caught, "
        f"{score['equivalent']} equivalent on these inputs: score {_percent(score['score'])}"
    )
    if not result["stimulus"]["outputs_changed"]:
        print(
            f"note: no output of the unmutated design changed in the {cycles} cycles, so only "
            "a mutant that changes a constant output is caught: give more --cycles, or check "
            "that the design takes the stimulus (its reset, its frames' size: --resolution)"
        )
    _print_modules(modules, campaign is not None and not _exit_code(result["baseline"]))
    if campaign is not None:
        _report_robot(
            out,
            result,
            result["robot_judge_s"],
            args.recordings,
            say,
            title=name,
            inputs="these inputs",
        )
    missed = [m for m in result["mutants"] if not m["unit"]["caught"]]
    if missed:
        print("equivalent on these inputs (first 10):")
        for m in missed[:10]:
            print(f"  {m['describe']}")
    print(f"wrote {os.path.join(out, 'mutants.json')}")
    return _exit_code(result["baseline"])


def _check(args):
    if not 1 <= args.mutants <= MAX_MUTANTS:
        raise UsageError(f"--mutants must be 1..{MAX_MUTANTS}, got {args.mutants}")
    if not 0 <= args.seed <= MAX_SEED:
        raise UsageError(f"--seed must be 0..{MAX_SEED}, got {args.seed}")
    if args.recordings is not None and args.recordings < 0:
        raise UsageError(f"--recordings must be >= 0, got {args.recordings}")
    if args.campaign is None and (
        args.workers
        or args.scheduler
        or args.resume
        or args.fork is not None
        or args.recordings is not None
    ):
        raise UsageError(
            "--workers, --scheduler, --resume, --fork/--no-fork and --recordings go with "
            "--campaign (the robot judge)"
        )
    args.recordings = 5 if args.recordings is None else args.recordings
    check_cluster_options(args.workers, args.scheduler)
    args.fork = True if args.fork is None else args.fork


def _percent(x):
    return "n/a" if x is None else f"{100 * x:.1f}%"


def main(argv=None, prog="fpga-robotics mutate"):
    args = build_parser(prog).parse_args(argv)
    _check(args)
    if args.design is not None and args.design != "follow_target":
        return _main_design(args)
    args.against = args.against or "model"
    given = args.param or args.define or args.cycles is not None or args.ports is not None
    if given or args.resolution:
        raise UsageError(
            "--param, --define, --ports, --cycles and --resolution go with --design REF, a "
            "design of your own, not FollowTarget (the default, and --design follow_target), "
            "whose frame size is --width and --height"
        )
    params = params_from_args(args)
    # The mutant netlist is built for this frame size and these values: every robot judge
    # run takes them.
    campaign = _campaign(args.campaign, params) if args.campaign is not None else None
    out = _out(args, f"n{args.mutants}-s{args.seed}")
    check_output_dir(out, what="output folder")
    _reach_scheduler(args.scheduler)

    try:
        with _removed_on_error(out, campaign):
            return _mutate_follow_target(args, params, campaign, out)
    except BackendError as exc:  # the netlist failed to build, or its reference to run
        raise UsageError(_one_line(exc)) from None


def _mutate_follow_target(args, params, campaign, out):
    """FollowTarget's mutants: listed, built, judged and reported in ``out``."""

    def say(text):
        if not args.quiet:
            print(text, file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    try:
        mutants = list_mutants(params, args.mutants, args.seed)
    except MutationError as exc:
        raise UsageError(str(exc).splitlines()[0]) from None
    key = mutants_key(repr(params), mutants)
    if args.resume and campaign is not None:
        check_resume(out, key, campaign)
    clear_earlier_run(out, args.resume and campaign is not None)
    netlist, ports = write_mutant_design(params, mutants, out)
    watch_ports = os.path.join(out, WATCH_PORTS_NAME)
    resolution = f"{params.width}x{params.height}"
    # The references' model (with the watch) builds while the unit judge runs.
    sets = design_sets(params)
    prebuilt = (
        start_prebuild(campaign, netlist, watch_ports, resolution, sets)
        if campaign is not None and args.fork
        else None
    )
    design = open_mutant_design(params, netlist, ports, on_build=lambda t: say(f"{t} ..."))
    build_s = time.perf_counter() - t0
    try:
        frames = judge_frames(params)
        try:
            golden = (
                golden_results(params, frames)
                if args.against == "model"
                else reference_results(design, frames)
            )
        except BackendError as exc:
            raise BackendError(f"--against design: the unmutated design fails: {exc}") from None
        t1 = time.perf_counter()
        verdicts = []
        for k, m in enumerate(mutants, start=1):
            verdicts.append(judge_mutant(design, m.index, frames, golden))
            if k == len(mutants) or k * 10 // len(mutants) != (k - 1) * 10 // len(mutants):
                say(
                    f"unit judge: {k}/{len(mutants)} mutants, "
                    f"{sum(v.caught for v in verdicts)} caught"
                )
        unit_s = time.perf_counter() - t1
    finally:
        design.close()

    unit = {v.index: v.caught for v in verdicts}
    robot_verdicts, baseline = {}, None
    cones, cone_s = None, None
    if campaign is not None:
        caught = [v.index for v in verdicts if v.caught]
        if args.fork:  # --no-fork: every run in full, as before
            t3 = time.perf_counter()
            try:
                cones = mutant_cones(params, [m for m in mutants if m.index in caught])
            except MutationError as exc:  # no verdict without a run then: all run
                say(f"fan-out cones: {str(exc).splitlines()[0]}; every mutant runs")
            cone_s = time.perf_counter() - t3
        t2 = time.perf_counter()
        baseline, robot_verdicts = robot_judge(
            campaign,
            netlist,
            ports,
            f"{params.width}x{params.height}",
            caught,
            out,
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            say=say,
            fork=args.fork,
            cones=cones,
            watch_ports=watch_ports,
            mutants=key,
            prebuilt=prebuilt,
            design=sets,
        )
        robot_s = time.perf_counter() - t2
    robot = {k: v["caught"] for k, v in robot_verdicts.items()}
    blind = set(blind_spots(unit, robot))
    score = unit_score(unit)
    modules = by_module(mutants, unit, robot)
    results = {
        "design": {"width": params.width, "height": params.height},
        "seed": args.seed,
        "against": args.against,
        "frames": len(frames),
        "build_and_list_s": round(build_s, 2),
        "unit_judge_s": round(unit_s, 2),
        "unit_mutants_per_minute": round(60 * len(mutants) / unit_s, 1) if unit_s else None,
        "unit": score,
        "robot": robot_score(unit, robot) if campaign is not None else None,
        "campaign": campaign.name if campaign is not None else None,
        "robot_judge_s": round(robot_s, 2) if campaign is not None else None,
        "cone_s": round(cone_s, 2) if cone_s is not None else None,
        "baseline": baseline,
        "modules": modules,
        "mutants": [
            {
                **{k: v for k, v in m.__dict__.items()},
                "sources": list(m.sources),
                "describe": m.describe(),
                "unit": {
                    "caught": v.caught,
                    "first_frame": v.first_frame,
                    "differing": v.differing,
                    "frames_differing": v.frames_differing,
                    "max_difference": v.max_difference,
                    "effect": v.effect(),
                },
                "robot": robot_verdicts.get(m.index),
                "blind_spot_reason": (
                    blind_spot_reason(v, params.width) if m.index in blind else None
                ),
            }
            for m, v in zip(mutants, verdicts)
        ],
    }
    write_json_atomic(os.path.join(out, "mutants.json"), results, what="mutation results")

    print(
        f"{len(mutants)} mutants of follow_target {params.width}x{params.height} "
        f"(seed {args.seed}), {len(frames)} unit frames; build {build_s:.1f} s, "
        f"unit judge {60 * len(mutants) / unit_s:.0f} mutants/min"
        + (f", fan-out cones {cone_s:.1f} s" if cone_s is not None else "")
    )
    against = "" if args.against == "model" else " (against the unmutated design)"
    print(
        f"unit judge{against}: {score['caught']} caught, {score['equivalent']} equivalent "
        f"on these frames: score {_percent(score['score'])}"
    )
    _print_modules(modules, campaign is not None and not _exit_code(baseline))
    if campaign is not None:
        _report_robot(
            out,
            results,
            robot_s,
            args.recordings,
            say,
            title=f"follow_target {params.width}x{params.height}",
            inputs="the unit frames",
        )
    missed = [m for m, v in zip(mutants, verdicts) if not v.caught]
    if missed:
        print("equivalent on the unit frames (first 10):")
        for m in missed[:10]:
            print(f"  {m.describe()}")
    print(f"wrote {os.path.join(out, 'mutants.json')}")
    return _exit_code(baseline)


if __name__ == "__main__":  # python -m fpga_robotics.cli.mutate: as fpga-robotics mutate
    from fpga_robotics.cli import run_command

    run_command("mutate")
