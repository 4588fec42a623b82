"""Copies of the gateware with one seeded bug, for showing that the formal checks bite.

``mutant(cls, old, new)`` compiles a copy of the module that defines ``cls`` with the text
``old`` (which must occur exactly once, so a change to the design makes the test fail loudly
instead of silently testing nothing) replaced by ``new``, and returns the copy's ``cls``.
The product is never touched: the copy lives in its own namespace.
"""

import inspect
import sys

__all__ = ["mutant"]


def mutant(cls, old, new, **names):
    """``cls`` from a copy of its module with ``old`` replaced by ``new``; ``names`` are
    extra globals of the copy (another mutant class the new text refers to)."""
    module = sys.modules[cls.__module__]
    source = inspect.getsource(module)
    count = source.count(old)
    if count != 1:
        raise AssertionError(f"{old!r} occurs {count} times in {module.__name__}, not once")
    namespace = {
        "__name__": f"{module.__name__}_mutant",
        "__package__": module.__package__,
        **names,
    }
    code = compile(source.replace(old, new), f"<{module.__name__} with a seeded bug>", "exec")
    exec(code, namespace)  # noqa: S102 - our own source, one line changed
    return namespace[cls.__name__]
