"""Closed-loop scenarios in a pytest suite: run a scenario with a design and assert its checks.

    from fpga_robotics.testing import run

    def test_stops_before_the_wall():
        result = run("wall_stop.toml", design="wall_stop.py:WallStop", params={"speed": 450})
        result.assert_passes()                       # every check of the scenario
        assert result.check("max_wall_collisions").status == "pass"
        assert result.trajectory["design.stopped"][-1] == 1

``run`` loads the scenario as ``fpga-robotics run --scenario`` does, with ``design`` in place
of its ``design.top`` (any design reference, docs/your_design.md), ``params`` as its
``[design.params]`` and ``overrides`` as ``--set KEY=VALUE`` items; relative paths are from
the current folder. A bad scenario or design raises ``UsageError`` with the one-line message
the command line prints.
"""

import json
from dataclasses import dataclass
from pathlib import Path

from fpga_robotics.hw.errors import UsageError
from fpga_robotics.loop.timings import run_scenario
from fpga_robotics.scenario.load import load_scenario, override_items

__all__ = ["Check", "Result", "run"]

_STATUS = {True: "pass", False: "fail", None: "n/a"}


@dataclass(frozen=True)
class Check:
    """One check of a run: ``status`` is ``"pass"``, ``"fail"`` or ``"n/a"`` (the design has
    no output that measures it); ``value`` what was measured, ``limit`` the scenario's."""

    name: str
    status: str
    value: object
    limit: object
    text: str


class Result:
    """A finished run: ``summary`` (the dict ``run --json`` writes), ``trajectory`` (numpy
    arrays per frame or row: ``x``, ``y``, ``distance_mm`` of a sensor, ``design.NAME`` of an
    extra output ...), ``events`` and the checks."""

    def __init__(self, run_result, scenario):
        self.summary = run_result.summary
        self.trajectory = run_result.trajectory
        self.events = run_result.events
        self.scenario = scenario

    @property
    def checks(self):
        """Every check, in the scenario's order."""
        return [
            Check(
                c["name"], _STATUS[c["passed"]], c.get("value"), c.get("limit"), c.get("text", "")
            )
            for c in self.summary.get("checks", ())
        ]

    @property
    def passed(self):
        return self.summary["verdict"] == "pass"

    def check(self, name):
        """The check ``name``; ``KeyError`` naming the scenario's checks if it has none."""
        for c in self.checks:
            if c.name == name:
                return c
        raise KeyError(
            f"scenario {self.scenario.name!r} has no check {name!r}; its checks: "
            f"{', '.join(c.name for c in self.checks) or 'none'}"
        )

    def assert_passes(self, *, allow_not_measured=False):
        """Raise ``AssertionError`` listing every failing check (and every check the design
        could not measure, unless ``allow_not_measured``)."""
        bad = [
            c
            for c in self.checks
            if c.status == "fail" or (c.status == "n/a" and not allow_not_measured)
        ]
        if not self.checks:
            raise AssertionError(
                f"scenario {self.scenario.name!r} has no checks: give it a [checks] table"
            )
        if bad:
            lines = [f"  [{c.status}] {c.name}: {c.text}" for c in bad]
            raise AssertionError(
                f"scenario {self.scenario.name!r} ({self.summary['verdict']}):"
                f" {len(bad)} of {len(self.checks)} checks not passed\n" + "\n".join(lines)
            )

    def __repr__(self):
        return (
            f"<Result {self.scenario.name} {self.summary['verdict']}: "
            f"{', '.join(f'{c.name}={c.status}' for c in self.checks)}>"
        )


def _absolute(reference):
    """A ``FILE.py:Name`` reference made absolute from the current folder (the scenario's
    folder is where a scenario file's own references start)."""
    where, sep, name = reference.rpartition(":")
    if sep and where.endswith(".py"):
        return f"{Path(where).expanduser().resolve()}:{name}"
    return reference


def _design_overrides(design, ports):
    items = []
    if design is not None:
        if not isinstance(design, str):
            raise UsageError(f"design must be a design reference (text), got {design!r}")
        if design.startswith("verilog:"):
            if ports is None:
                raise UsageError(f"design {design!r} needs ports= (its port map, docs/foreign.md)")
            files = [str(Path(f).resolve()) for f in design[len("verilog:") :].split(",") if f]
            items += [
                f"design.top={json.dumps('verilog:' + ','.join(files))}",
                f"design.ports={json.dumps(str(Path(ports).resolve()))}",
            ]
        else:
            items.append(f"design.top={json.dumps(_absolute(design))}")
    elif ports is not None:
        raise UsageError(
            "ports= is the port map of a Verilog design: it goes with design='verilog:FILE.v'"
        )
    return items


def _checked_params(params):
    """``params`` as ``load_scenario`` takes them: a dict of keyword-argument names."""
    if params is None:
        return None
    if not isinstance(params, dict):
        raise UsageError(f"params must be a dict of the design's keyword arguments, got {params!r}")
    for name in params:
        if not (isinstance(name, str) and name.isidentifier()):
            raise UsageError(f"params: {name!r} is not a keyword-argument name")
    return params


def run(
    scenario,
    *,
    design=None,
    params=None,
    defines=None,
    overrides=(),
    seed=None,
    backend="auto",
    ports=None,
    recorder=None,
):
    """Run ``scenario`` (a .toml path or a shipped scenario's name) in closed loop.

    Parameters
    ----------
    design : str, optional
        A design reference to run instead of the scenario's ``design.top``:
        ``"my_design.py:MyDesign"``, ``"package.module:Name"``, a built-in name, or
        ``"verilog:top.v"`` with ``ports="ports.toml"``.
    params : dict, optional
        ``[design.params]`` values (the design's keyword arguments) as Python values:
        ``None``, an enum member or a dict reach the design as given, each checked against
        its signature as ``[design.params]`` are; a Verilog design's top-module
        parameters (numbers, booleans, text; checked against the design's own).
    defines : dict, optional
        A Verilog design's `define macros (``[design.defines]``; ``True``: defined without a
        value).
    overrides : list of str
        ``KEY=VALUE`` items, as ``--set`` takes them (``"sim.duration=5"``).
    seed : int, optional
        Fixes every random choice; default the scenario's seed.
    backend : str
        ``"auto"`` (the fastest compiled simulator), ``"cxxrtl"``, ``"verilator"``,
        ``"pysim"`` (or ``"model"`` for the built-in FollowTarget).
    recorder : optional
        A viewer recorder (``fpga_robotics.viz.open_recorder``), not closed here.
    """
    items = [*_design_overrides(design, ports), *override_items(overrides)]
    if defines is not None:
        if not isinstance(defines, dict):
            raise UsageError(f"defines must be a dict of macro names, got {defines!r}")
        items += [f"design.defines.{n}={json.dumps(v)}" for n, v in defines.items()]
    loaded = load_scenario(str(scenario), items, design_params=_checked_params(params))
    return Result(run_scenario(loaded, seed=seed, backend=backend, recorder=recorder), loaded)
