"""Before a campaign runs: every run checked as ``run`` would check it, named by its identity,
and grouped by the design it needs (each parameter set is built once)."""

from dataclasses import dataclass, field, replace
from pathlib import Path

from fpga_robotics.hw.errors import UsageError

from .campaign import _how_option, run_identity, toml_value
from .fork_groups import world_key
from .runner import _design_key, design_digest, load_run

__all__ = ["Plan", "make_plan"]


@dataclass
class Plan:
    runs: list  # RunSpec, in campaign order
    ids: dict = field(default_factory=dict)  # RunSpec -> identity
    names: dict = field(default_factory=dict)  # RunSpec -> scenario name
    frames: dict = field(default_factory=dict)  # RunSpec -> (frames, pixels)
    builds: dict = field(default_factory=dict)  # design key -> argv of one run
    worlds: dict = field(default_factory=dict)  # RunSpec -> its world (fork_groups), or None
    build_keys: dict = field(default_factory=dict)  # RunSpec -> its design key (builds)

    def keep_first(self, n):
        """Only the first ``n`` runs, and only the builds they need (``--max-runs``)."""
        self.runs = self.runs[:n]
        needed = {self.build_keys[spec] for spec in self.runs}
        self.builds = {key: argv for key, argv in self.builds.items() if key in needed}


def _concrete_backend(spec, scenario, shadow):
    """The backend ``run --backend`` takes for the run (its designs as loaded, overrides
    and all), so that each worker builds with the same choice: ``auto`` stays beside a
    Verilog design (CXXRTL where Yosys reads it, else Verilator: sim/backends/foreign_choice.py,
    design by design); other designs take the fastest compiled backend here."""
    if spec.backend != "auto" or scenario.foreign is not None or getattr(shadow, "foreign", None):
        return spec.backend
    from ..sim.backends import fastest_backend_name  # lazy: the simulator (~0.5 s)

    return fastest_backend_name()


def make_plan(campaign):
    """Check every run (``UsageError`` naming the run's scenario and overrides) and name it.
    Runs differing only by seed share one check. Two scenario files of one name, and a
    known limit naming a scenario the campaign does not run, are usage errors too."""
    from ..cli.run import PortMapUnpaired  # lazy: the run stack (~1 s)
    from ..sim.backends import BACKEND_NAMES  # lazy: the simulator (~0.5 s)

    plan = Plan(runs=[])
    checked = {}
    digests = {}  # design key -> design_digest
    files_named = {}  # scenario name -> {resolved file: (as the campaign gives it, file)}
    where = f"{campaign.source}: " if campaign.source else ""
    for spec in campaign.runs:
        if spec.backend not in ("auto", *BACKEND_NAMES):
            how = _how_option("backend", spec.backend, campaign.command_line)
            file = "" if how.startswith("--") else where
            raise UsageError(
                f"{file}{how}: the backend must be one of auto, {', '.join(BACKEND_NAMES)}"
            )
        shape = replace(spec, seed=0)
        if shape not in checked:
            try:
                args, scenario, shadow_params = load_run(spec.argv())
            except UsageError as exc:
                if isinstance(exc, PortMapUnpaired):
                    exc = _port_map_unpaired(spec, campaign.command_line) or exc
                    raise UsageError(f"{_run_named(spec)}: {exc}") from None
                shadow = f"--shadow {spec.shadow}"
                if str(exc).startswith(shadow) and not campaign.command_line.get("shadow"):
                    # run names its option; the campaign file gave the value
                    how = f"{where}shadow = {toml_value(spec.shadow)}"
                    raise UsageError(
                        f"{how}, in the {_run_named(spec)}{str(exc)[len(shadow) :]}"
                    ) from None
                how = _given_as(spec, str(exc))
                if how is None:  # the scenario's own values, or its design
                    raise UsageError(f"{_run_named(spec)}: {exc}") from None
                # Named as given: an option, or the campaign file's words with the file.
                file = "" if how.startswith("--") else where
                raise UsageError(f"{file}{how}, in the {_run_named(spec)}: {exc}") from None
            # A shadow design's scenario (None: no shadow, or FollowTarget parameters).
            shadow = shadow_params if hasattr(shadow_params, "sim") else None
            # Loading depends on the backend only for a Verilog design, where auto stays:
            # the run as loaded is the run on the concrete backend.
            args.backend = _concrete_backend(spec, scenario, shadow)
            key = (_design_key(args, scenario), repr(shadow_params))
            if key not in digests:
                digests[key] = design_digest(args, scenario, shadow)
            frames = round(scenario.sim.duration * scenario.camera.fps)
            checked[shape] = (
                key,
                scenario,
                digests[key],
                frames,
                scenario.camera.width * scenario.camera.height,
                world_key(args, scenario, shadow_params),
                args.backend,
            )
            plan.builds.setdefault(key, replace(spec, backend=args.backend).argv())
            files_named.setdefault(scenario.name, {}).setdefault(
                str(Path(scenario.source).resolve()) if scenario.source else spec.scenario,
                (spec.scenario, scenario.source),
            )
        key, scenario, digest, frames, pixels, world, backend = checked[shape]
        spec = replace(spec, backend=backend)
        plan.build_keys[spec] = key
        plan.worlds[spec] = world
        plan.runs.append(spec)
        plan.ids[spec] = run_identity(spec, scenario.source, digest)
        plan.names[spec] = scenario.name
        plan.frames[spec] = (frames, pixels)
    _one_file_per_name(files_named, where)
    _each_run_once(plan, where)
    _limits_name_run_scenarios(campaign, set(files_named), where)
    return plan


def _first_values(spec, n):
    """``spec`` with only the first ``n`` of its values, in the order run applies them: its
    ``--set`` items, then its resolution, then its duration."""
    options = [o for o in ("resolution", "duration") if getattr(spec, o) is not None]
    past_items = max(0, n - len(spec.fixed) - len(spec.overrides))
    return replace(
        spec,
        fixed=spec.fixed[:n],
        overrides=spec.overrides[: max(0, n - len(spec.fixed))],
        **dict.fromkeys(options[past_items:]),
    )


def _given_as(spec, message):
    """How the value a run fails to load with was given (``spec.origins``): the first value
    with which the run, loaded with the values up to it, fails with ``message``; None when it
    fails so with none of them (its scenario, its design)."""
    for n in range(len(spec.origins) + 1):
        try:
            load_run(_first_values(spec, n).argv())
        except UsageError as exc:
            if str(exc) == message:
                return spec.origins[n - 1] if n else None
    return None


def _run_named(spec):
    """A run in a message: its scenario as the campaign gives it, and its overrides."""
    what = " ".join(spec.set_items())
    return f"run of {spec.scenario}{' with ' + what if what else ''}"


def _port_map_unpaired(spec, command_line):
    """run's message for a Verilog design without a port map (or a port map without one) in
    the campaign file's words, when the file gave the value (None: the command line did, and
    run's message names its option)."""
    if spec.ports is None:
        if command_line.get("design"):
            return None
        return f'design = {toml_value(spec.design)} needs ports = "PORTS.toml" (its port map)'
    if command_line.get("ports"):
        return None
    return (
        f"ports = {toml_value(spec.ports)} is the port map of a Verilog design, and the run "
        f'has none: give design = "verilog:FILE.v" with it, or leave ports out'
    )


def _shown(given, source):
    """A scenario as the campaign gives it, with its file when the name does not say it."""
    if source and Path(given).resolve() != Path(source).resolve():
        return f"{given} ({source})"
    return given


def _one_file_per_name(files_named, where):
    """Rows, pass rates and known limits go by a scenario's name: two files of one name
    would be counted as one scenario."""
    for name, files in files_named.items():
        if len(files) > 1:
            (a, sa), (b, sb) = list(files.values())[:2]
            raise UsageError(
                f"{where}scenarios {_shown(a, sa)} and {_shown(b, sb)} are two files with the "
                f"same name {name!r} (results are grouped by name): give one of them another "
                f'name = "..."'
            )


def _each_run_once(plan, where):
    """Rows go by a run's identity: one scenario file given by two paths (or two copies of
    it) would make one row of two runs."""
    spec_of_identity = {}
    for spec in plan.runs:
        twin = spec_of_identity.setdefault(plan.ids[spec], spec)
        if twin is not spec:
            raise UsageError(
                f"{where}{_run_named(twin)} and {_run_named(spec)} (seed {spec.seed}) are one "
                f"run (the same scenario content, seed and overrides): give each run once"
            )


def _limits_name_run_scenarios(campaign, names, where):
    """A known limit's ``scenarios`` must be scenarios the campaign runs (a typo would
    otherwise explain nothing, silently); unless the command line chose the scenarios."""
    if campaign.scenarios_replaced:
        return
    for i, entry in enumerate(campaign.known_limits):
        stray = [n for n in entry["scenarios"] if n not in names]
        if stray:
            raise UsageError(
                f"{where}known_limits[{i}]: scenarios names {stray[0]!r}, which the campaign "
                f"does not run (its scenarios are named {', '.join(sorted(names))})"
            )
