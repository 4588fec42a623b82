"""``fpga-robotics mutate``: how many gateware bugs do the unit frames catch?

Generates N mutants of ``FollowTarget`` with Yosys's ``mutate`` pass (seeded), builds one
Verilator model holding all of them (``mutsel`` picks one), runs each through the unit judge
(every output against the golden model on fixed frames), and writes ``mutants.json`` into
the output folder; the terminal gets the score, the score per component and the mutants no
frame shows.
"""

import argparse
import os
import sys
import time

from ..errors import UsageError
from ..param_options import add_param_arguments, params_from_args
from ..sim.files import check_output_dir, write_json_atomic
from ..sim.mutation import MutationError, list_mutants
from .design import open_mutant_design, write_mutant_design
from .scores import by_module, unit_score
from .unit_judge import golden_results, judge_frames, judge_mutant

__all__ = ["main"]

DEFAULT_MUTANTS = 100
MAX_MUTANTS = 4000


def build_parser(prog):
    p = argparse.ArgumentParser(
        prog=prog,
        description="Mutation coverage: Yosys mutants of the design, one build for all of "
                    "them, each judged against the golden model on fixed frames "
                    "(docs/mutation.md).")
    p.add_argument("--mutants", type=int, default=DEFAULT_MUTANTS, metavar="N",
                   help=f"how many mutants (default {DEFAULT_MUTANTS}, at most {MAX_MUTANTS})")
    p.add_argument("--seed", type=int, default=1, metavar="S",
                   help="Yosys's choice of mutants (default 1); the same seed, the same list")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output folder (default runs/mutation/n<N>-s<S>/)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    add_param_arguments(p)
    return p


def _check(args):
    if not 1 <= args.mutants <= MAX_MUTANTS:
        raise UsageError(f"--mutants must be 1..{MAX_MUTANTS}, got {args.mutants}")
    if args.seed < 0:
        raise UsageError(f"--seed must be >= 0, got {args.seed}")


def _percent(x):
    return "n/a" if x is None else f"{100 * x:.1f}%"


def main(argv=None, prog="python -m fpga_robotics.mutation"):
    args = build_parser(prog).parse_args(argv)
    _check(args)
    params = params_from_args(args)
    out = args.out or os.path.join("runs", "mutation", f"n{args.mutants}-s{args.seed}")
    check_output_dir(out, what="output folder")

    def say(text):
        if not args.quiet:
            print(text, file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    try:
        mutants = list_mutants(params, args.mutants, args.seed)
    except MutationError as exc:
        raise UsageError(str(exc).splitlines()[0]) from None
    netlist, ports = write_mutant_design(params, mutants, out)
    design = open_mutant_design(params, netlist, ports, on_build=lambda t: say(f"{t} ..."))
    build_s = time.perf_counter() - t0
    try:
        frames = judge_frames(params)
        golden = golden_results(params, frames)
        t1 = time.perf_counter()
        verdicts = []
        for k, m in enumerate(mutants, start=1):
            verdicts.append(judge_mutant(design, m.index, frames, golden))
            if k == len(mutants) or k * 10 // len(mutants) != (k - 1) * 10 // len(mutants):
                say(f"unit judge: {k}/{len(mutants)} mutants, "
                    f"{sum(v.caught for v in verdicts)} caught")
        unit_s = time.perf_counter() - t1
    finally:
        design.close()

    unit = {v.index: v.caught for v in verdicts}
    score = unit_score(unit)
    modules = by_module(mutants, unit)
    write_json_atomic(os.path.join(out, "mutants.json"), {
        "design": {"width": params.width, "height": params.height},
        "seed": args.seed,
        "frames": len(frames),
        "build_and_list_s": round(build_s, 2),
        "unit_judge_s": round(unit_s, 2),
        "unit_mutants_per_minute": round(60 * len(mutants) / unit_s, 1) if unit_s else None,
        "unit": score,
        "modules": modules,
        "mutants": [{**{k: v for k, v in m.__dict__.items()}, "sources": list(m.sources),
                     "describe": m.describe(),
                     "unit": {"caught": v.caught, "first_frame": v.first_frame,
                              "differing": v.differing, "effect": v.effect()}}
                    for m, v in zip(mutants, verdicts)],
    }, what="mutation results")

    print(f"{len(mutants)} mutants of follow_target {params.width}x{params.height} "
          f"(seed {args.seed}), {len(frames)} unit frames; build {build_s:.1f} s, "
          f"unit judge {60 * len(mutants) / unit_s:.0f} mutants/min")
    print(f"unit judge: {score['caught']} caught, {score['equivalent']} equivalent on these "
          f"frames: score {_percent(score['score'])}")
    width = max(len(name) for name in modules)
    for name, row in modules.items():
        print(f"  {name:<{width}}  {row['unit_caught']:>4}/{row['total']:<4} caught")
    missed = [m for m, v in zip(mutants, verdicts) if not v.caught]
    if missed:
        print("equivalent on the unit frames (first 10):")
        for m in missed[:10]:
            print(f"  {m.describe()}")
    print(f"wrote {os.path.join(out, 'mutants.json')}")
    return 0
