"""The fast test tier (``pytest -m "not slow"``) builds no Verilator model and runs no place
and route: the entry points of those builds raise in a test not marked ``slow``.

The check is on the entry points, not on the build cache, so a test that needs such a model
fails in the fast tier whether or not the model happens to be cached on this machine.
"""

import importlib
import importlib.abc
import sys

#: module -> [(object path inside it, what it builds)]; each is replaced by a function that
#: raises ``SlowBuildInFastTier``.
ENTRY_POINTS = {
    "fpga_robotics.sim.backends.verilator": [("verilator_build_plan", "a Verilator model")],
    "fpga_robotics.sim.backends.foreign": [("foreign_build_plan", "a Verilator model")],
    "fpga_robotics.sim.pins.compiled": [("VerilatorPins.plan", "a Verilator model")],
    "fpga_robotics.flow.board": [("find_yowasp_tools", "place and route (nextpnr)")],
}


class SlowBuildInFastTier(AssertionError):
    """A test not marked ``slow`` reached a slow build."""


def _refuse(what, test):
    def refuse(*args, **kwargs):
        raise SlowBuildInFastTier(
            f"{test} builds {what} but is not marked slow: the fast tier "
            f"(pytest -m \"not slow\") builds no Verilator model and runs no place and route; "
            f"mark the test @pytest.mark.slow"
        )

    return refuse


def _targets(module, test):
    for path, what in ENTRY_POINTS[module.__name__]:
        owner_path, _, attr = path.rpartition(".")
        owner = module
        for part in filter(None, owner_path.split(".")):
            owner = getattr(owner, part)
        replacement = _refuse(what, test)
        if isinstance(owner, type):  # a class attribute: keep it a plain function
            replacement = staticmethod(replacement)
        yield owner, attr, replacement


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
