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

from amaranth.asserts import AnySeq
from amaranth.hdl import Fragment
from amaranth.lib.wiring import In

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
    and ``name.covers``: empty when its class declares no ``formal_properties``."""
    sample = make_dut()
    cls = type(sample)
    Fragment.get(sample, None)  # elaborated once: its class is all that is needed of it
    if not callable(getattr(cls, PROPERTY_HOOK, None)):
        return []
    mode = getattr(cls, "formal_mode", "bmc")
    depth = int(getattr(cls, "formal_depth", DEFAULT_DEPTH))
    doc = (getattr(cls, PROPERTY_HOOK).__doc__ or "").strip().splitlines()
    checks = [
        FormalCheck(
            f"{name}.properties",
            mode,
            depth,
            doc[0] if doc else f"the properties {cls.__name__} declares",
            build=lambda dut=None: DeclaredHarness(dut or make_dut(), PROPERTY_HOOK),
            make_dut=make_dut,
        )
    ]
    if callable(getattr(cls, COVER_HOOK, None)):
        doc = (getattr(cls, COVER_HOOK).__doc__ or "").strip().splitlines()
        cover_depth = int(getattr(cls, "formal_cover_depth", depth))
        checks.append(
            FormalCheck(
                f"{name}.covers",
                "cover",
                cover_depth,
                doc[0] if doc else f"the covers {cls.__name__} declares",
                build=lambda dut=None: DeclaredHarness(dut or make_dut(), COVER_HOOK),
                make_dut=make_dut,
            )
        )
    return checks
