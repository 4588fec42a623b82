"""The fast test tier (``pytest -m "not slow"``) builds no Verilator model and runs no place
and route: the entry points of those builds raise in a test not marked ``slow``.

A Verilator model is refused where it is fetched from the build cache, built or not, so a
test that needs one fails in the fast tier whether or not the model happens to be cached on
this machine; a test that only reaches the Verilator flow's own checks (a missing compiler)
stays in the fast tier.
"""

import importlib
import importlib.abc
import sys


def _verilator_model(args, kwargs):
    """Whether a ``get_or_build`` call is for a Verilator model (frame, foreign or pin level),
    by its entry name; a cache hit counts as much as a build."""
    name = str(args[0] if args else kwargs.get("name", ""))
    return name.startswith(("verilator-", "pins-verilator-"))


#: module -> [(function inside it, what it builds, which calls are refused (None: all))].
ENTRY_POINTS = {
    "fpga_robotics.sim.backends.build_cache": [
        ("get_or_build", "a Verilator model", _verilator_model)
    ],
    "fpga_robotics.flow.board": [("find_yowasp_tools", "place and route (nextpnr)", None)],
}


class SlowBuildInFastTier(AssertionError):
    """A test not marked ``slow`` reached a slow build."""


def _guarded(original, what, refused, test):
    def guarded(*args, **kwargs):
        if refused is None or refused(args, kwargs):
            raise SlowBuildInFastTier(
                f"{test} builds {what} but is not marked slow: the fast tier "
                f'(pytest -m "not slow") builds no Verilator model and runs no place and '
                f"route; mark the test @pytest.mark.slow"
            )
        return original(*args, **kwargs)

    guarded.guarded = original
    return guarded


def _targets(module, test):
    for attr, what, refused in ENTRY_POINTS[module.__name__]:
        yield module, attr, _guarded(getattr(module, attr), what, refused, test)


def forbid(monkeypatch, test):
    """Replace every entry point for the duration of ``test`` (a pytest node id)."""
    for name in ENTRY_POINTS:
        for owner, attr, replacement in _targets(importlib.import_module(name), test):
            monkeypatch.setattr(owner, attr, replacement)


class _PatchOnImport(importlib.abc.MetaPathFinder):
    """Replaces the entry points of a module as soon as it is imported (so that a command run
    by a test pays nothing for the modules it does not use)."""

    def __init__(self, test):
        self.test = test

    def find_spec(self, name, path, target=None):
        if name not in ENTRY_POINTS:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(name, path, target)
            if spec is not None:
                break
        else:
            return None
        exec_module = spec.loader.exec_module

        def exec_and_patch(module):
            exec_module(module)
            for owner, attr, replacement in _targets(module, self.test):
                setattr(owner, attr, replacement)

        spec.loader.exec_module = exec_and_patch
        return spec


def forbid_on_import(test):
    """In a process a fast-tier test started: replace the entry points when imported."""
    sys.meta_path.insert(0, _PatchOnImport(test))
