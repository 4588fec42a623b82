"""Campaign files: which runs a campaign makes, each as the ``run`` command that replays it.

A campaign is a TOML file (docs/campaigns.md)::

    name = "filter_tuning"                  # default: the file's stem
    description = "..."
    scenarios = ["divider", "lighting"]     # shipped names or .toml paths
    seeds = "0-19"                          # "A-B" (inclusive) or a list of integers
    backend = "model"                       # as run --backend (default auto)
    resolution = "160x120"                  # optional, as run --resolution
    duration = 10.0                         # optional, as run --duration
    shadow = "published"                    # optional, as run --shadow
    design = "my_design.py:MyDesign"        # optional, as run --design (verilog:top.v with
                                            # ports)
    ports = "top_ports.toml"
    set = ["robot.mass=12"]                 # optional fixed overrides, as run --set
    timeout = 120.0                         # optional per-run limit (s)

    [grid]                                  # every key run --set accepts, a list of values
    "design.diff_min" = [4, 6, 8]
    "lighting.ambient" = [0.25, 0.7]
    # "design.top" = ["follow_target", "verilog:top.v"]: designs as an axis (file references
    # in grid, sets and set values are relative to this file, as design and ports are; the
    # campaign's ports go with every verilog: design)

    [[sets]]                                # optional explicit override sets
    "robot.mass" = 12

    [[known_limits]]                        # optional: a failure that is a limit of the design
    check = "found_min_fraction"            # the check that fails (or a list of checks)
    when = {"camera.resolution" = "80x60"}  # optional: the runs' overrides it applies to
    scenarios = ["divider"]                 # optional: the scenarios it applies to (by name)
    reason = "at 80x60 the target is ..."   # why: shown in the report

The runs are, for every scenario and seed, the cartesian product of the grid plus each
explicit set. A run *is* its ``python -m fpga_robotics.run`` argument list: the workers parse
it with ``run``'s own parser, so the replay command of a row is the run itself.
"""

import difflib
import hashlib
import itertools
import json
import math
import os
import re
import shlex
import tomllib
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.sim.files import NotTextError, read_user_text

from .. import __version__

__all__ = [
    "Campaign",
    "CampaignError",
    "RunSpec",
    "load_campaign",
    "parse_seeds",
    "shipped_campaigns",
    "toml_value",
]

#: Keys a campaign file may hold.
KEYS = (
    "name",
    "description",
    "scenarios",
    "seeds",
    "backend",
    "resolution",
    "duration",
    "shadow",
    "design",
    "ports",
    "set",
    "timeout",
    "grid",
    "sets",
    "known_limits",
)
#: Keys of a ``[[known_limits]]`` entry.
LIMIT_KEYS = ("check", "reason", "when", "scenarios")

#: At most this many runs in one campaign (a typo in a seed range must not plan 10**12).
MAX_RUNS = 1_000_000


class CampaignError(UsageError):
    """A malformed campaign file or option: one line saying what and how to fix it."""


@dataclass(frozen=True)
class RunSpec:
    """One run of a campaign."""

    scenario: str  # as the campaign names it (shipped name or path)
    seed: int
    overrides: tuple  # ((key, value), ...) from the grid or a set, in file order
    backend: str
    resolution: str | None = None
    duration: float | None = None
    shadow: str | None = None
    design: str | None = None
    ports: str | None = None
    fixed: tuple = ()  # the campaign's fixed ``set`` items (KEY=VALUE text)
    #: How each of ``set_items()``, then the resolution and the duration, was given (the
    #: campaign file's words or the option), for messages.
    origins: tuple = field(default=(), compare=False)

    def set_items(self):
        return [*self.fixed, *(f"{k}={toml_value(v)}" for k, v in self.overrides)]

    def argv(self):
        """The ``python -m fpga_robotics.run`` arguments of this run."""
        out = ["--scenario", self.scenario, "--backend", self.backend, "--seed", str(self.seed)]
        if self.resolution is not None:
            out += ["--resolution", self.resolution]
        if self.duration is not None:
            out += ["--duration", repr(float(self.duration))]
        for item in self.set_items():
            out += ["--set", item]
        if self.shadow is not None:
            out += ["--shadow", self.shadow]
        if self.design is not None:
            out += ["--design", self.design]
        if self.ports is not None:
            out += ["--ports", self.ports]
        return out

    def replay(self):
        return shlex.join(["python", "-m", "fpga_robotics.run", *self.argv()])


@dataclass
class Campaign:
    name: str
    description: str
    runs: list
    axes: list  # grid/set keys, the override columns of the results
    timeout: float | None = None
    source: str = ""
    identities: dict = field(default_factory=dict)  # filled by plan.identify
    #: ``[[known_limits]]``: failures that are limits of the design, each with its reason.
    known_limits: list = field(default_factory=list)
    #: What the command line gave (``load_campaign``'s ``command_line``).
    command_line: dict = field(default_factory=dict)

    @property
    def scenarios_replaced(self):
        """The command line replaced the scenarios (``--scenarios``): a known limit may then
        name a scenario of the file that this campaign does not run (it does not apply)."""
        return bool(self.command_line.get("scenarios"))


def toml_value(v):
    """``v`` as a TOML value, so that ``--set key=<text>`` reads it back as ``v``."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return (
            "{" + ", ".join(f"{_toml_string(str(k))} = {toml_value(x)}" for k, x in v.items()) + "}"
        )
    raise CampaignError(f"cannot write {v!r} as a --set value")


def _toml_string(text):
    """A TOML basic string: JSON's escapes (not of non-ASCII characters), DEL escaped too."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


#: How seeds are written in a campaign file (the messages of ``parse_seeds``).
SEED_FORMS = '"A-B" (e.g. "0-19") or a list of integers'


def parse_seeds(value, where="seeds", forms=SEED_FORMS):
    """``"0-19"``, ``"7"``, an integer or a list of integers → a list of seeds. ``where``
    and ``forms``: the setting and how seeds are written there, for the messages."""
    from fpga_robotics.scenario.load import MAX_SEED  # lazy: the run stack (~1 s)

    if isinstance(value, bool):
        raise CampaignError(f"{where} must be {forms}, got {value!r}")
    if isinstance(value, int):
        seeds = [value]
    elif isinstance(value, str):
        text = value.strip()
        lo, sep, hi = text.partition("-")
        try:
            a = int(lo)
            b = int(hi) if sep else a
        except ValueError:
            raise CampaignError(f"{where} must be {forms}, got {value!r}") from None
        if b < a:
            raise CampaignError(
                f'{where} range {value!r} is empty: write the lower seed first (e.g. "{b}-{a}")'
            )
        if b - a + 1 > MAX_RUNS:
            raise CampaignError(
                f"{where} range {value!r} has {b - a + 1} seeds; at most {MAX_RUNS}"
            )
        seeds = list(range(a, b + 1))
    elif isinstance(value, list):
        if not all(isinstance(s, int) and not isinstance(s, bool) for s in value):
            raise CampaignError(f"{where} list must hold integers only, got {value!r}")
        seeds = list(dict.fromkeys(value))
    else:
        raise CampaignError(f"{where} must be {forms}, got {value!r}")
    if not seeds:
        raise CampaignError(f'{where} is empty: give at least one seed (e.g. "0-4")')
    bad = [s for s in seeds if not 0 <= s <= MAX_SEED]
    if bad:
        raise CampaignError(f"{where}: seed {bad[0]} is out of range 0..{MAX_SEED}")
    return seeds


def _flatten(table, prefix, where):
    """``{"design": {"diff_min": [4, 5]}}`` or ``{"design.diff_min": [4, 5]}`` → pairs."""
    out = []
    for key, value in table.items():
        path = f"{prefix}{key}"
        # "" = [...] names no scenario key; the runs would fail on "unknown scenario key ''".
        if not key.strip():
            raise CampaignError(f"{where} {path!r} is empty: name a scenario key (e.g. robot.mass)")
        if isinstance(value, dict):
            out += _flatten(value, f"{path}.", where)
        elif isinstance(value, list):
            if not value:
                raise CampaignError(
                    f"{where} {path!r} has no values: give a list of at "
                    f"least one value (e.g. {path} = [4, 6])"
                )
            out.append((path, value))
        else:
            raise CampaignError(
                f"{where} {path!r} must be a list of values, got {value!r} "
                f"(write {path} = [{toml_value(value)}])"
            )
    return out


def _set_items(items, where):
    if isinstance(items, str):
        items = [items]
    if not isinstance(items, list) or not all(isinstance(i, str) and "=" in i for i in items):
        raise CampaignError(f'{where} must be a list of "KEY=VALUE" strings, got {items!r}')
    return tuple(items)


def _twice(values):
    """The first value of ``values`` that an earlier one equals, else None."""
    return next((v for i, v in enumerate(values) if v in values[:i]), None)


def _shown_combo(combo):
    return " ".join(f"{k}={toml_value(v)}" for k, v in combo)


def _how_axis(key, command_line):
    return f"--grid {key}" if key in command_line.get("grid", ()) else f"the [grid] axis {key}"


def _how_set_item(item, command_line):
    return (
        f"--set {item}" if item in command_line.get("set", ()) else f"set item {toml_value(item)}"
    )


def _how_option(option, value, command_line):
    """A value the campaign gives every run (``duration``, ``design``...) as it was given."""
    return f"--{option} {value}" if command_line.get(option) else f"{option} = {toml_value(value)}"


def _combos(data, command_line):
    """The override sets: the grid's cartesian product, then the explicit sets, and how each
    override of each was given. A run given twice (a value listed twice on an axis, a set
    equal to a grid run or to another set) is an error: its rows would be merged into one."""
    combos = []
    origins = []
    axes = []
    if "grid" in data:
        grid = data["grid"]
        if not isinstance(grid, dict) or not grid:
            raise CampaignError(
                "grid is empty: give at least one key with a list of values "
                '(e.g. [grid] "design.diff_min" = [4, 6, 8]), or leave it out'
            )
        pairs = _flatten(grid, "", "grid key")
        for key, vs in pairs:
            twice = _twice([toml_value(v) for v in vs])
            if twice is not None:
                raise CampaignError(
                    f"{_how_axis(key, command_line)} lists {twice} twice: give each value once"
                )
        axes = [k for k, _ in pairs]
        values = [[_hashable(v) for v in vs] for _, vs in pairs]
        combos = [tuple(zip(axes, combo)) for combo in itertools.product(*values)]
        origins = [tuple(_how_axis(k, command_line) for k in axes)] * len(combos)
    if "sets" in data:
        sets = data["sets"]
        if not isinstance(sets, list) or not sets or not all(isinstance(s, dict) for s in sets):
            raise CampaignError(
                "sets must be a non-empty list of tables ([[sets]] with KEY = VALUE lines)"
            )
        # A run as its overrides, in any order (a table's keys have none).
        runs = {_run_of(combo): f"the grid run {_shown_combo(combo)}" for combo in combos}
        for i, s in enumerate(sets):
            if not s:
                raise CampaignError(f"sets[{i}] is empty: give at least one KEY = VALUE")
            items = tuple(_flatten_values(s, ""))
            run = _run_of(items)
            if run in runs:
                raise CampaignError(f"sets[{i}] repeats {runs[run]}: give each run once")
            runs[run] = f"sets[{i}]"
            origins.append((f"sets[{i}]",) * len(items))
            for k, _ in items:
                if k not in axes:
                    axes.append(k)
            combos.append(items)
    return combos or [()], origins or [()], axes


def _run_of(combo):
    return frozenset((k, toml_value(v)) for k, v in combo)


def _flatten_values(table, prefix):
    out = []
    for key, value in table.items():
        if isinstance(value, dict):
            out += _flatten_values(value, f"{prefix}{key}.")
        else:
            out.append((f"{prefix}{key}", _hashable(value)))
    return out


class _Table(dict):
    """An inline table of an override value (a piece of furniture, a person) that can be
    hashed, as a run's overrides must be; never changed once made. ``toml_value`` writes it
    back as an inline table and the results as a JSON object, as a dict."""

    __slots__ = ()

    def __hash__(self):
        return hash(frozenset(self.items()))


def _hashable(value):
    """A list value (a colour, a start position, waypoints) as tuples and an inline table as
    a ``_Table``, all the way down: a run's overrides are hashable."""
    if isinstance(value, list):
        return tuple(_hashable(v) for v in value)
    if isinstance(value, dict):
        return _Table((k, _hashable(v)) for k, v in value.items())
    return value


#: Override keys that choose the design, which a campaign's ``design`` chooses for every run.
DESIGN_CHOICE_KEYS = ("design.top", "design.verilog")


def _given_once(data, fixed, command_line):
    """Refuse a value the campaign gives every run (a ``set`` item; its seeds, ``duration``,
    ``resolution``; ``design``, and with it ``ports``) that the runs' overrides give too (a
    grid axis, a ``[[sets]]`` table, a ``set`` item): a run takes one of them (run's last
    ``--set``, its ``--seed``, ``--design``) while its row would be labelled with the other.
    Each is named as it was given: by its option when the command line gave it, else in the
    file's words."""
    every = {}  # key -> how the campaign gives it to every run
    # run's --duration and --resolution are --set items of these keys, after the runs' own.
    for key, option in (("sim.duration", "duration"), ("camera.resolution", "resolution")):
        if data.get(option) is not None:
            every[key] = _how_option(option, data[option], command_line)
    if data.get("design") is not None:
        how = _how_option("design", data["design"], command_line)
        every.update(dict.fromkeys(DESIGN_CHOICE_KEYS, how))
        if data.get("ports") is not None:  # run's --ports replaces the design's design.ports
            every["design.ports"] = _how_option("ports", data["ports"], command_line)
    given = []  # (key, how, varied) of each override
    for item in fixed:
        given.append((item.partition("=")[0].strip(), _how_set_item(item, command_line), False))
    for key, _ in _flatten(data.get("grid") or {}, "", "grid key"):
        given.append((key, _how_axis(key, command_line), True))
    for i, table in enumerate(data.get("sets") or []):
        given += [(key, f"sets[{i}]", True) for key, _ in _flatten_values(table, "")]
    for key, how, varied in given:
        if key == "seed":  # run's --seed, which the campaign gives every run, wins
            raise CampaignError(
                f"{how} sets the scenario's seed, which the campaign's seeds give every run: "
                f"list the seeds there (e.g. seeds = [1, 2], or --seeds 1,2)"
            )
        if key in every:
            raise CampaignError(
                f"{every[key]} gives every run its {key}, and {how} "
                f"{'varies it' if varied else 'gives it too'}: give it in one of them"
            )
        if not varied:
            every[key] = how  # a later --set replaces an earlier set item of the key


def _comparable(value):
    """An override value as the runs' values are compared (a list as a tuple)."""
    if isinstance(value, (list, tuple)):
        return tuple(_comparable(v) for v in value)
    return value


def _when_matches_a_run(where, when, combos, replaced):
    """A known limit's ``when`` must match some run: a value no run has (a typo, ``"3000"``
    for 3000) would otherwise explain nothing, silently. An axis the command line replaced
    (``--grid``) may leave a value out (the entry then does not apply)."""
    wanted = {k: _comparable(v) for k, v in when.items() if k not in replaced}
    runs = [{k: _comparable(v) for k, v in combo} for combo in combos]
    for key, value in wanted.items():
        values = []
        for run in runs:
            if key in run and run[key] not in values:
                values.append(run[key])
        if value not in values:
            raise CampaignError(
                f"{where}: when {key} = {toml_value(when[key])} matches no run (the "
                f"campaign's values of {key}: {', '.join(toml_value(v) for v in values)})"
            )
    if not any(all(k in run and run[k] == v for k, v in wanted.items()) for run in runs):
        shown = ", ".join(f"{k} = {toml_value(when[k])}" for k in wanted)
        raise CampaignError(f"{where}: when {shown} matches no run (no run has them all)")


def _known_limits(data, axes, combos, replaced=()):
    """The ``[[known_limits]]`` entries, checked: each names a registered check and a reason,
    optionally ``when`` (override key -> value, keys among the grid/sets axes, matching
    some run of ``combos`` but on the axes the command line ``replaced``) and
    ``scenarios``."""
    from fpga_robotics.checks.registry import check_names  # lazy: the run stack (~1 s)

    limits = data.get("known_limits", [])
    if not isinstance(limits, list) or not all(isinstance(x, dict) for x in limits):
        raise CampaignError(
            "known_limits must be a list of tables ([[known_limits]] with "
            "check = NAME and reason = TEXT)"
        )
    out = []
    for i, entry in enumerate(limits):
        where = f"known_limits[{i}]"
        unknown = [k for k in entry if k not in LIMIT_KEYS]
        if unknown:
            raise CampaignError(
                f"{where}: unknown key {unknown[0]!r}; an entry holds {', '.join(LIMIT_KEYS)}"
            )
        checks, reason = entry.get("check"), entry.get("reason")
        checks = [checks] if isinstance(checks, str) else checks
        if (
            not isinstance(checks, list)
            or not checks
            or any(c not in check_names() for c in checks)
        ):
            raise CampaignError(
                f"{where}: check must name a registered check (or a list of "
                f"them), got {entry.get('check')!r}"
            )
        if not isinstance(reason, str) or not reason.strip():
            raise CampaignError(
                f"{where}: give a reason (why the design fails {', '.join(checks)} there)"
            )
        when = (
            dict(_flatten_values(entry.get("when", {}), ""))
            if isinstance(entry.get("when", {}), dict)
            else None
        )
        if when is None:
            raise CampaignError(f"{where}: when must be a table of override KEY = VALUE")
        stray = [k for k in when if k not in axes]
        if stray:
            raise CampaignError(
                f"{where}: when names {stray[0]!r}, which no grid axis or set "
                f"of the campaign varies"
            )
        _when_matches_a_run(where, when, combos, replaced)
        scenarios = entry.get("scenarios", [])
        if isinstance(scenarios, str):
            scenarios = [scenarios]
        if not isinstance(scenarios, list) or not all(isinstance(x, str) for x in scenarios):
            raise CampaignError(f"{where}: scenarios must be a list of scenario names")
        out.append(
            {"check": checks, "reason": reason.strip(), "when": when, "scenarios": list(scenarios)}
        )
    return out


def _typed(data, key, types, what):
    value = data.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, types):
        raise CampaignError(f"{key} must be {what}, got {value!r}")
    return value


def shipped_campaigns():
    """Names → paths of the campaigns shipped with the package."""
    folder = resources.files("fpga_robotics.sweep") / "campaigns"
    return {
        e.name[:-5]: str(e)
        for e in sorted(folder.iterdir(), key=lambda e: e.name)
        if e.name.endswith(".toml")
    }


def _resolve(name_or_path):
    text = str(name_or_path)
    if not text.strip():  # Path("") would be the current folder
        raise CampaignError("the campaign is empty; give a shipped name or a .toml file")
    path = Path(text)
    if path.is_file():
        return path
    shipped = shipped_campaigns()
    if text in shipped:
        return Path(shipped[text])
    if path.is_dir():
        raise CampaignError(f"campaign {text!r} is a folder; give a .toml file")
    raise CampaignError(
        f"unknown campaign {text!r}: no such file, and the shipped campaigns "
        f"are {', '.join(shipped)}"
    )


def read_campaign_file(name_or_path):
    """The campaign file's table (checked for unknown keys) and its path."""
    path = _resolve(name_or_path)
    try:
        data = tomllib.loads(read_user_text(path))
    except tomllib.TOMLDecodeError as exc:
        raise CampaignError(f"{path}: malformed TOML: {exc}") from None
    except (OSError, NotTextError) as exc:
        raise CampaignError(f"cannot read campaign file {path}: {exc}") from None
    unknown = [k for k in data if k not in KEYS]
    if unknown:
        close = difflib.get_close_matches(unknown[0], KEYS, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise CampaignError(
            f"{path}: unknown key {unknown[0]!r}{hint}; a campaign holds {', '.join(KEYS)}"
        )
    data.setdefault("name", path.stem)
    _file_paths(data, path.parent)
    return data, path


def load_campaign(data, *, source="", command_line=None):
    """The ``Campaign`` of a checked table (``read_campaign_file`` plus command-line
    options merged in). Scenarios and overrides are checked by ``plan.make_plan``.
    ``command_line``: what of ``data`` the command line gave, ``{"scenarios": True,
    "backend": True, "duration": True, "resolution": True, "shadow": True, "design": True,
    "ports": True, "set": [ITEM, ...],
    "grid": [KEY, ...]}`` (any left out), so that messages name those values by their
    options."""
    where = f"{source}: " if source else ""
    command_line = command_line or {}
    try:
        name = _typed(data, "name", str, "a string") or "campaign"
        # The name makes the default results folder: a plain file name.
        name = re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip(".-")[:64] or "campaign"
        description = _typed(data, "description", str, "a string") or ""
        scenarios = data.get("scenarios")
        if isinstance(scenarios, str):
            scenarios = [scenarios]
        if (
            not scenarios
            or not isinstance(scenarios, list)
            or not all(isinstance(s, str) and s for s in scenarios)
        ):
            raise CampaignError(
                "scenarios must be a non-empty list of shipped scenario names or .toml paths"
            )
        twice = _twice(scenarios)
        if twice is not None:
            how = "--scenarios" if command_line.get("scenarios") else "scenarios"
            raise CampaignError(f"{how} lists {twice} twice: give each scenario once")
        seeds = parse_seeds(data.get("seeds", "0"))
        backend = _typed(data, "backend", str, "a backend name")
        backend = "auto" if backend is None else backend  # "" is checked, not taken for auto
        resolution = _typed(data, "resolution", str, '"WxH"')
        duration = _typed(data, "duration", (int, float), "a number of seconds")
        if duration is not None and not 0 < duration < math.inf:
            raise CampaignError(f"duration must be a finite number of seconds > 0, got {duration}")
        timeout = _typed(data, "timeout", (int, float), "a number of seconds")
        if timeout is not None and not 0 < timeout < math.inf:
            raise CampaignError(f"timeout must be a finite number of seconds > 0, got {timeout}")
        fixed = _set_items(data.get("set", []), "set")
        combos, origins, axes = _combos(data, command_line)
        _given_once(data, fixed, command_line)
        known_limits = _known_limits(data, axes, combos, command_line.get("grid", ()))
        base = RunSpec(
            scenario="",
            seed=0,
            overrides=(),
            backend=backend,
            resolution=resolution,
            duration=duration,
            shadow=_typed(data, "shadow", str, 'a shadow spec (e.g. "published")'),
            design=_typed(
                data, "design", str, 'a design reference ("FILE.py:Name", "verilog:FILE.v")'
            ),
            ports=_typed(data, "ports", str, "a port map path"),
            fixed=fixed,
        )
        count = len(scenarios) * len(seeds) * len(combos)
        if count > MAX_RUNS:
            raise CampaignError(f"the campaign has {count} runs; at most {MAX_RUNS}")
        fixed_how = tuple(_how_set_item(item, command_line) for item in fixed)
        options_how = tuple(
            _how_option(option, data[option], command_line)
            for option in ("resolution", "duration")
            if data.get(option) is not None
        )
        ports_how = base.ports and _how_option("ports", base.ports, command_line)
        shapes = [
            _with_ports(
                replace(base, overrides=combo, origins=(*fixed_how, *how, *options_how)),
                ports_how,
            )
            for combo, how in zip(combos, origins)
        ]
        runs = [
            replace(shape, scenario=sc, seed=seed)
            for sc in scenarios
            for shape in shapes
            for seed in seeds
        ]
    except CampaignError as exc:
        raise CampaignError(f"{where}{exc}") from None
    return Campaign(
        name=name,
        description=description,
        runs=runs,
        axes=axes,
        timeout=timeout,
        source=source,
        known_limits=known_limits,
        command_line=command_line,
    )


def _with_ports(spec, ports_how):
    """The campaign's ``ports`` go with every Verilog design of its runs: with no campaign
    ``design``, a run whose overrides make ``design.top`` a ``verilog:`` design gets them as
    ``design.ports`` (unless it sets that itself), and a run whose overrides name another
    design, or give the scenario's own Verilog design its ``design.ports``, takes none.
    ``ports_how``: how the campaign gave its ports (for messages)."""
    if spec.ports is None or spec.design is not None:
        return spec
    from fpga_robotics.scenario.load import _parse_value  # lazy: the run stack (~1 s)

    overrides = {}
    for item in spec.fixed:
        key, _, text = item.partition("=")
        overrides[key.strip()] = _parse_value(text)
    overrides.update(spec.overrides)
    if "design.top" not in overrides:
        # The scenario's own design (its design.verilog): --ports replaces its map, unless
        # the run gives one (run's --ports would replace that too).
        return replace(spec, ports=None) if "design.ports" in overrides else spec
    top = overrides["design.top"]
    if not (isinstance(top, str) and top.startswith("verilog:")) or "design.ports" in overrides:
        return replace(spec, ports=None)
    ports = f"design.ports={toml_value(os.path.abspath(spec.ports))}"
    n = len(spec.fixed)
    origins = (*spec.origins[:n], ports_how, *spec.origins[n:])
    return replace(spec, ports=None, fixed=(*spec.fixed, ports), origins=origins)


def run_identity(spec, scenario_source, design_digest=""):
    """The hash that names a run: scenario content, overrides, seed, backend, resolution,
    duration, its designs as built (``runner.design_digest``) and the package version (the
    same run in another folder or campaign has the same identity)."""
    h = hashlib.sha256()
    argv = spec.argv()
    argv[1] = "<scenario>"  # the content counts, not the path
    blob = {"argv": argv, "version": __version__, "design": design_digest}
    h.update(json.dumps(blob, sort_keys=True).encode())
    try:
        h.update(Path(scenario_source).read_bytes())
    except OSError:
        h.update(str(scenario_source).encode())
    return h.hexdigest()[:16]


def _near(value, base):
    """A path given in a campaign file, relative to the file's folder, as a path from here
    (so that replay commands work where the campaign was started); an absolute one as given
    (it works from any folder, as the user wrote it)."""
    if (
        not isinstance(value, str)
        or "/" not in value
        and not value.endswith((".toml", ".v", ".py", ".sv"))
    ):
        return value
    path = Path(value)
    if path.is_absolute():
        return value
    candidate = base / path
    if candidate.exists() or not path.exists():
        path = candidate
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)


#: Override keys whose values name files (a design reference, Verilog files, a port map).
DESIGN_FILE_KEYS = ("design.top", "design.verilog", "design.ports")


def _absolute(text, base):
    """A file path given in a campaign file, relative to the file's folder (or, when only
    there, to the current folder), made absolute: a run's override is read relative to its
    scenario's folder, so it must not depend on a folder at all."""
    path = Path(text).expanduser()
    if not path.is_absolute():
        candidate = base / path
        if candidate.exists() or not path.exists():
            path = candidate
    return os.path.abspath(path)


def _design_value(key, value, base):
    """An override value of ``key`` (one of ``DESIGN_FILE_KEYS``) with the files it names
    made absolute; a built-in design's or a module's name stays as it is."""
    if key == "design.top" and isinstance(value, str):
        if value.startswith("verilog:"):
            files = value[len("verilog:") :].split(",")
            return "verilog:" + ",".join(_absolute(f, base) for f in files if f)
        where, sep, name = value.rpartition(":")
        if sep and where.endswith(".py"):
            return f"{_absolute(where, base)}:{name}"
        return value
    if key == "design.ports" and isinstance(value, str) and value.strip():
        return _absolute(value, base)
    if key == "design.verilog":
        if isinstance(value, str) and value.strip():
            return _absolute(value, base)
        if isinstance(value, list):
            return [_absolute(f, base) if isinstance(f, str) and f.strip() else f for f in value]
    return value


def _design_paths(table, base, axis, prefix=""):
    """The design file references among ``table``'s override keys (nested or dotted) made
    absolute, in place; ``axis``: each value is a list of values (a grid)."""
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict):
            _design_paths(value, base, axis, f"{path}.")
        elif path in DESIGN_FILE_KEYS:
            if axis and isinstance(value, list):
                table[key] = [_design_value(path, v, base) for v in value]
            elif not axis:
                table[key] = _design_value(path, value, base)


def _design_set_item(item, base):
    """A ``set`` item ``KEY=VALUE`` whose key names files, those made absolute."""
    from fpga_robotics.scenario.load import _parse_value  # lazy: the run stack (~1 s)

    key, sep, text = item.partition("=")
    if not sep or key.strip() not in DESIGN_FILE_KEYS:
        return item
    value = _parse_value(text)
    new = _design_value(key.strip(), value, base)
    return item if new == value else f"{key.strip()}={toml_value(new)}"


def _file_paths(data, base):
    """Paths in a campaign file are relative to the file: its scenarios, design and ports
    (as paths from the current folder, for the replay commands) and the design files its
    grid, sets, set items and known limits name (absolute: a run's override is read from its
    scenario's folder)."""
    if isinstance(data.get("grid"), dict):
        _design_paths(data["grid"], base, axis=True)
    if isinstance(data.get("sets"), list):
        for table in data["sets"]:
            if isinstance(table, dict):
                _design_paths(table, base, axis=False)
    if isinstance(data.get("known_limits"), list):
        for entry in data["known_limits"]:
            if isinstance(entry, dict) and isinstance(entry.get("when"), dict):
                _design_paths(entry["when"], base, axis=False)
    items = data.get("set")
    if isinstance(items, str):
        items = [items]
    if isinstance(items, list) and all(isinstance(i, str) for i in items):
        data["set"] = [_design_set_item(i, base) for i in items]
    if isinstance(data.get("scenarios"), list):
        data["scenarios"] = [_near(s, base) for s in data["scenarios"]]
    elif isinstance(data.get("scenarios"), str):
        data["scenarios"] = [_near(data["scenarios"], base)]
    if isinstance(data.get("ports"), str):
        data["ports"] = _near(data["ports"], base)
    for key in ("design", "shadow"):  # design references, as run --design and --shadow
        value = data.get(key)
        if isinstance(value, str) and value.startswith("verilog:"):
            files = value[len("verilog:") :].split(",")
            data[key] = "verilog:" + ",".join(_near(f, base) for f in files if f)
        elif isinstance(value, str) and ".py:" in value:
            where, _, name = value.rpartition(":")
            data[key] = f"{_near(where, base)}:{name}"
