"""Campaign runs that share a world, run as one reference run and forked variants.

Runs of one scenario and seed whose scenarios differ only in their design or checks (a
parameter sweep, design references), in one timing, see the same world until their designs
drive differently: such a group is one Dask task that runs its first member in full as a fork
reference (fpga_robotics.loop.fork, pin_fork) and every other as a variant of it, each
re-simulated in the world only from where it parts. Every member's row is the row its own
full run gives (the times excepted). Runs with a shadow design or ``[runtime]`` values, and
campaigns that record every run, are run one by one as before; so is everything with
``sweep --no-fork``.
"""

import json

from fpga_robotics.loop.fork import VARIANT_SECTIONS

from . import runner

__all__ = ["MEMBER_TOPIC", "execute_group", "fork_groups", "spread", "world_key"]

#: The Dask event topic under which a group's task publishes each run's outcome (JSON text,
#: tagged as the run) as soon as it has it: when the worker dies later in the group, the
#: campaign keeps the runs that finished.
MEMBER_TOPIC = "fpga-robotics-sweep-group-runs"


def world_key(args, scenario, shadow_params):
    """What runs of one shape must share to be forked from one another (with the seed), or
    None for a run that is run on its own."""
    if shadow_params is not None or args.shadow is not None or getattr(args, "runtime", None):
        return None
    if scenario.sim.timing not in ("compressed", "real_clock"):
        return None
    world = {k: v for k, v in scenario.data.items() if k not in VARIANT_SECTIONS}
    # The design resolves sim.timing = "auto": runs in two timings share no world.
    world["resolved timing"] = scenario.sim.timing
    return json.dumps(world, sort_keys=True, default=repr)


def fork_groups(specs, worlds):
    """``specs`` as groups to run: runs of one world (``worlds[spec]``, None alone) and seed
    together, in the order their first member comes."""
    groups, index = [], {}
    for spec in specs:
        world = worlds.get(spec)
        if world is None:
            groups.append([spec])
            continue
        key = (world, spec.seed)
        if key not in index:
            index[key] = len(groups)
            groups.append([])
        groups[index[key]].append(spec)
    return groups


def spread(groups, workers):
    """``groups`` cut into at least ``workers`` groups where they have the runs for it: a
    group is one task on one worker, so a campaign of fewer groups than workers (a grid over
    design values only, one seed) would leave workers idle. Each piece costs one more reference
    run, and ends sooner; the pieces of a group are near-equal runs of its order, the largest
    pieces cut first."""
    pieces = [1] * len(groups)
    while sum(pieces) < workers:
        can = [i for i, g in enumerate(groups) if pieces[i] < len(g)]
        if not can:
            break
        i = max(can, key=lambda k: -(-len(groups[k]) // pieces[k]))
        pieces[i] += 1
    out = []
    for group, n in zip(groups, pieces, strict=True):
        size, extra = divmod(len(group), n)
        start = 0
        for k in range(n):
            end = start + size + (k < extra)
            out.append(group[start:end])
            start = end
    return out


def execute_group(argvs, timeouts, tags):
    """Run a group's runs (``run`` argument lists of one world), the first that completes
    as the reference, the others forked from it; returns one outcome per run as
    ``runner.execute`` does, each also published as it comes (``MEMBER_TOPIC``)."""
    from fpga_robotics.loop.pin_fork import reference_run  # lazy: the run stack (~1 s)
    from fpga_robotics.loop.timings import run_scenario  # lazy: the run stack (~1 s)

    outcomes, reference = [], None
    worker = runner._current_worker()
    for argv, timeout, tag in zip(argvs, timeouts, tags, strict=True):
        with runner.RunOutcome() as outcome:
            args, scenario, _shadow = runner._loaded(argv)
            design, _ = runner._designs_for(args, scenario, None)
            outcome.deadline = deadline = runner._Deadline(timeout, runner._fault(args), tag)
            with outcome.running():
                if reference is None:
                    reference = reference_run(
                        scenario, design=design, seed=args.seed, progress=deadline
                    )
                    result = reference.result
                else:
                    try:
                        result = reference.run_variant(design, scenario, progress=deadline)
                    except ValueError:  # not a variant of it after all: a run of its own
                        result = run_scenario(
                            scenario, seed=args.seed, backend=design, progress=deadline
                        )
            outcome.record(result)
        outcomes.append(outcome.out)
        if worker is not None:
            worker.log_event(MEMBER_TOPIC, {"tag": tag, "outcome": json.dumps(outcome.out)})
    return outcomes
