"""Formal properties a design declares about its own ports (docs/formal.md, "Properties of
your own design").

A ``wiring.Component`` declares them with methods:

- ``formal_properties(self, m)`` adds ``Assert``/``Assume`` statements to ``m`` (the harness's
  module: ``m.d.comb``/``m.d.sync``, the design as its submodule ``dut``); checked in the
  mode of the class attribute ``formal_mode`` (``"bmc"`` unless it says ``"prove"``) to
  ``formal_depth`` cycles (default ``DEFAULT_DEPTH``);
- ``formal_covers(self, m)``, optional, adds ``Cover`` statements (and ``Assume``s of their
  own): each must be reachable within ``formal_cover_depth`` cycles (default
  ``formal_depth``), a cover check of its own.

Every input port (of nested interfaces too) is free (``AnySeq``): the solver picks each
cycle's value; the design's ``Assume`` statements are the only constraints. Registers start
at their initial values (the harness's ``sync`` domain has no reset).
"""

import inspect
import traceback
import warnings
from pathlib import Path

from amaranth.asserts import AnySeq
from amaranth.back import rtlil
from amaranth.hdl import Fragment, UnusedElaboratable
from amaranth.lib.wiring import In

from ..errors import USER_CODE_ERRORS, UsageError
from .harness import FormalCheck, Harness

__all__ = ["COVER_HOOK", "DEFAULT_DEPTH", "PROPERTY_HOOK", "DeclaredHarness", "declared_checks"]

PROPERTY_HOOK = "formal_properties"
COVER_HOOK = "formal_covers"
#: Cycles searched when the design does not say (``formal_depth``).
DEFAULT_DEPTH = 20


class DeclaredHarness(Harness):
    """The design with free inputs and its own ``hook`` adding the properties."""

    def __init__(self, dut, hook):
        super().__init__()
        self.dut, self.hook = dut, hook

    def check(self, m):
        m.submodules.dut = dut = self.dut
        for _path, member, value in dut.signature.flatten(dut):
            if member.is_port and member.flow == In:
                m.d.comb += value.eq(AnySeq(member.shape))
        getattr(dut, self.hook)(m)


def declared_checks(name, make_dut):
    """The ``FormalCheck`` list of a design built by ``make_dut()``, named ``name.properties``
    and ``name.covers``: empty when its class declares no ``formal_properties``. A mode or
    depth out of range, a hook that raises (or adds statements Amaranth refuses), a
    ``formal_properties`` without an ``Assert`` and a ``formal_covers`` without a ``Cover`` are
    a ``UsageError`` naming the design, here rather
    than once the checks run."""
    sample = make_dut()
    cls = type(sample)
    Fragment.get(sample, None)  # elaborated once: its class is all that is needed of it
    if not callable(getattr(cls, PROPERTY_HOOK, None)):
        return []
    mode = getattr(cls, "formal_mode", "bmc")
    if mode not in ("bmc", "prove"):
        raise UsageError(f'design {name}: formal_mode must be "bmc" or "prove", not {mode!r}')
    depth = _cycles(name, cls, "formal_depth", DEFAULT_DEPTH)
    hooks = [(PROPERTY_HOOK, "properties", mode, depth)]
    if callable(getattr(cls, COVER_HOOK, None)):
        hooks.append(
            (COVER_HOOK, "covers", "cover", _cycles(name, cls, "formal_cover_depth", depth))
        )
    checks = []
    for hook, part, hook_mode, hook_depth in hooks:
        build = _builder(make_dut, hook)
        text = _converted(name, cls, hook, build())
        # SymbiYosys passes a run with nothing to check or reach: it would show nothing.
        if hook == COVER_HOOK and '\\FLAVOR "cover"' not in text:
            raise UsageError(
                f"design {name}: {COVER_HOOK} adds no Cover statement; add one "
                f"(m.d.comb += Cover(...)) or leave the method out"
            )
        if hook == PROPERTY_HOOK and '\\FLAVOR "assert"' not in text:
            raise UsageError(
                f"design {name}: {PROPERTY_HOOK} adds no Assert statement; add one "
                f'(m.d.comb += Assert(..., "what is wrong")) or leave the method out'
            )
        doc = (getattr(cls, hook).__doc__ or "").strip().splitlines()
        promise = doc[0] if doc else f"the {part} {cls.__name__} declares"
        checks.append(
            FormalCheck(f"{name}.{part}", hook_mode, hook_depth, promise, build, make_dut)
        )
    return checks


def _builder(make_dut, hook):
    return lambda dut=None: DeclaredHarness(dut or make_dut(), hook)


def _cycles(name, cls, attribute, default):
    value = getattr(cls, attribute, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise UsageError(
            f"design {name}: {attribute} must be a whole number of cycles, at least 1, "
            f"not {value!r}"
        )
    return value


def _converted(name, cls, hook, harness):
    """``harness`` in RTLIL, converted once here so that a hook that raises is one line before
    any check runs (the checks convert it again, each in its own worker)."""
    try:
        return rtlil.convert(harness, ports=harness.ports())
    except USER_CODE_ERRORS as exc:  # the design's own code may raise anything
        # The harness and design are never used now: no warning for each when collected.
        warnings.filterwarnings("ignore", category=UnusedElaboratable)
        source = inspect.getsourcefile(getattr(cls, hook))
        lines = [f.lineno for f in traceback.extract_tb(exc.__traceback__) if f.filename == source]
        where = f" ({Path(source).name}:{lines[-1]})" if lines else ""
        message = (str(exc).strip().splitlines() or ["(no message)"])[0]
        raise UsageError(
            f"design {name}: {hook} raised {type(exc).__name__}: {message}{where}"
        ) from None
