"""``fpga-robotics bench mutant_replay``: the most a forked mutant run can save.

A mutant's forked run that never parts from the unmutated design's still replays the mutant
netlist on every recorded frame (fpga_robotics.loop.fork): only the world (rendering,
physics) is saved. This benchmark runs a scenario once with the mutant netlist at
``mutsel = 0`` on Verilator (as the robot judge runs it) as a fork reference, then replays
the netlist alone on the recorded frames (as a mutant's run does; then with its watch
output watched, as the robot judge's unmutated runs do), and FollowTarget's own model on the
same frames on Verilator and CXXRTL, one process, CPU time. The replay's share of the full
run is what a mutant that never parts still costs: the fork's speed-up is at most its
inverse.
"""

import os
import tempfile
import time

from fpga_robotics.bench import scaffold
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.loop.compressed import make_backend
from fpga_robotics.loop.fork import ReferenceRun
from fpga_robotics.mutation.design import (
    WATCH_PORTS_NAME,
    open_mutant_design,
    write_mutant_design,
)
from fpga_robotics.scenario.load import ScenarioError, load_scenario, parse_resolution
from fpga_robotics.sim.mutation import MAX_MUTANT_SEED, list_mutants

__all__ = ["main", "replay_ms"]


def replay_ms(design, seen, repeats):
    """The least CPU milliseconds a frame over ``repeats`` replays of ``design`` (reset
    first) on ``seen``, the recorded ``(rgb, colour code)`` of every frame."""
    best = None
    for _ in range(repeats):
        design.reset()
        t0 = time.process_time()
        for rgb, color in seen:
            design.process_frame(rgb, color)
        cpu = time.process_time() - t0
        best = cpu if best is None else min(best, cpu)
    return 1000.0 * best / len(seen)


def _options(p):
    p.add_argument("--scenario", default="follow_person")
    p.add_argument("--resolution", default="160x120", help="camera and design resolution")
    p.add_argument("--duration", type=float, default=15.0, help="simulated seconds")
    p.add_argument("--mutants", type=int, default=60, help="mutants in the netlist")
    p.add_argument("--seed", type=int, default=0, help="Yosys's mutant seed")


def _check(args):
    if not 0 < args.duration <= 600:
        raise UsageError(f"--duration must be in (0, 600] s, got {args.duration}")
    if not 1 <= args.mutants <= 1000:
        raise UsageError(f"--mutants must be in 1..1000, got {args.mutants}")
    if not 0 <= args.seed <= MAX_MUTANT_SEED:
        raise UsageError(f"--seed must be 0..{MAX_MUTANT_SEED}, got {args.seed}")
    try:
        parse_resolution(args.resolution)
    except ScenarioError as exc:
        raise UsageError(f"--resolution: {exc}") from None


def run(args):
    w, h = parse_resolution(args.resolution)
    scenario = load_scenario(
        args.scenario, [f"sim.duration={args.duration!r}", f'camera.resolution="{w}x{h}"']
    )
    scaffold.check_follow_target_scenario(scenario, "mutant_replay")  # FollowTarget mutants
    params = scenario.params
    mutants = list_mutants(params, args.mutants, args.seed)
    with tempfile.TemporaryDirectory(prefix="fr-bench-mutants-") as folder:
        netlist, ports = write_mutant_design(params, mutants, folder)
        design = open_mutant_design(params, netlist, ports)
        try:
            t0 = time.process_time()
            reference = ReferenceRun(scenario, design=design)
            full_cpu = time.process_time() - t0
            seen = reference._loop.seen
            netlist_ms = replay_ms(design, seen, args.repeats)
        finally:
            design.close()
        watched = open_mutant_design(params, netlist, os.path.join(folder, WATCH_PORTS_NAME))
        try:
            watched_ms = replay_ms(watched, seen, args.repeats)
        finally:
            watched.close()
    own = {}
    for name in ("verilator", "cxxrtl"):
        backend = make_backend(name, params)
        try:
            own[name] = replay_ms(backend, seen, args.repeats)
        finally:
            backend.close()
    frames = len(seen)
    full_ms = 1000.0 * full_cpu / frames
    share = netlist_ms / full_ms
    print(
        f"{scenario.name} at {w}x{h}, {frames} frames; {len(mutants)} mutants of seed "
        f"{args.seed} in the netlist (CPU time a frame, least of {args.repeats} replays)"
    )
    print(f"  full run, mutant netlist at mutsel=0 (Verilator)   {full_ms:7.2f} ms")
    print(f"  the netlist alone on the recorded frames           {netlist_ms:7.2f} ms")
    print(f"  the same with its watch output watched             {watched_ms:7.2f} ms")
    print(f"  FollowTarget's own model alone, Verilator          {own['verilator']:7.2f} ms")
    print(f"  FollowTarget's own model alone, CXXRTL             {own['cxxrtl']:7.2f} ms")
    print(
        f"  a mutant run that never parts costs at least {share:.0%} of its full run: "
        f"forking gains at most {1 / share:.2f}x"
    )
    return {
        "frames": frames,
        "full_ms": full_ms,
        "netlist_ms": netlist_ms,
        "watched_ms": watched_ms,
        "own_verilator_ms": own["verilator"],
        "own_cxxrtl_ms": own["cxxrtl"],
        "fork_ceiling": 1 / share,
    }


main = scaffold.command(
    run, __doc__, name="mutant_replay", options=_options, check=_check, repeats=3
)
