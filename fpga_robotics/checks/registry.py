"""The registry of checks: every check a scenario's ``[checks]`` table may set, by name.

The shipped checks (``shipped.py``) and any a user adds with ``register_check`` live here
alike; the scenario loader validates limits against it, ``evaluate_checks`` judges a run with
it, and the docs' table of checks is tested against it. The verdict of a run: ``fail`` when a
check failed, else ``n/a`` when checks were set and none could judge, else ``pass``.
"""

from collections.abc import Mapping

from fpga_robotics.checks.check import Check, judge
from fpga_robotics.checks.shipped import SHIPPED_CHECKS

__all__ = [
    "CHECKS",
    "CHECK_OUTPUTS",
    "check_named",
    "check_names",
    "evaluate_checks",
    "register_check",
    "unregister_check",
    "verdict",
]

_REGISTRY = {}


def register_check(check=None, /, **fields):
    """Add a check: a ``Check``, or its fields as keywords (``register_check(name=...,
    metric=..., compare="max", meaning=..., message=...)``). Returns the ``Check``. A name
    already registered is an error (``unregister_check`` first to replace one)."""
    if check is None:
        check = Check(**fields)
    elif fields or not isinstance(check, Check):
        raise TypeError("register_check takes a Check or its fields as keywords")
    if check.name in _REGISTRY:
        raise ValueError(f"a check named {check.name!r} is already registered")
    _REGISTRY[check.name] = check
    return check


def unregister_check(name):
    """Remove the check ``name`` (a user's; removing a shipped one breaks the scenarios that
    set it)."""
    del _REGISTRY[name]


for _check in SHIPPED_CHECKS:
    register_check(_check)


def check_named(name):
    return _REGISTRY[name]


def check_names():
    """Every registered check's name, in registration order."""
    return list(_REGISTRY)


class _Limits(Mapping):
    """name -> ``(kind, (lowest, highest, unit), meaning)`` of every registered check, as the
    scenario loader reads it (a live view: a check registered later is in it)."""

    def __getitem__(self, name):
        c = _REGISTRY[name]
        return (c.kind, c.limits, c.meaning)

    def __iter__(self):
        return iter(list(_REGISTRY))

    def __len__(self):
        return len(_REGISTRY)


class _Outputs(Mapping):
    """name -> the design outputs a check is measured from (checks that need some)."""

    def __getitem__(self, name):
        outputs = _REGISTRY[name].outputs
        if not outputs:
            raise KeyError(name)
        return outputs

    def __iter__(self):
        return iter([n for n, c in _REGISTRY.items() if c.outputs])

    def __len__(self):
        return sum(1 for c in _REGISTRY.values() if c.outputs)


#: Pass criteria a scenario may state: name -> (type, (lowest, highest, unit), meaning).
CHECKS = _Limits()
#: The design outputs each check needs (those that need any).
CHECK_OUTPUTS = _Outputs()


def evaluate_checks(checks, m):
    """The scenario's checks (name -> limit) against the metrics ``m``: a list of result
    dicts, in order (``check.judge``): ``status`` "pass", "fail" or "n/a" (``reason`` says why;
    ``passed`` is True, False or None alike)."""
    out = []
    for name, limit in checks.items():
        if name not in _REGISTRY:  # validated by the scenario loader; keep a clear message
            raise ValueError(f"unknown check {name!r}")
        out.append(judge(_REGISTRY[name], limit, m))
    return out


def verdict(check_results):
    """``"fail"`` when a check failed; ``"n/a"`` when checks were set and none could judge
    (not a pass: nothing was shown); ``"pass"`` otherwise (n/a checks do not count; a run
    without checks passes)."""
    if any(c["passed"] is False for c in check_results):
        return "fail"
    if check_results and all(c["passed"] is None for c in check_results):
        return "n/a"
    return "pass"


def sensor_check(name, limit, m):
    """``(passed, text)`` of the check ``name`` against the metrics ``m`` (``passed`` None when
    it cannot judge)."""
    (c,) = evaluate_checks({name: limit}, m)
    return c["passed"], c["text"]
