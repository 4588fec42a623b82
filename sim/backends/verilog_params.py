"""A Verilog design's parameters and `define macros as the user gives them (``--param``,
``--define``, ``[design.params]``, ``[design.defines]``; docs/foreign.md), as every tool here
takes them alike: the parameters on the top's instance in the generated wrapper (which both
Verilator and Yosys read), ``-G`` where Verilator reads the top alone, ``chparam`` where Yosys
does; the macros as ```define`` lines of a file read before the design's own.
"""

import re
from dataclasses import dataclass

from .port_map import PortMapError

__all__ = ["DEFINES_FILE", "VerilogOverrides"]

#: The generated file of the ```define`` lines, read before the design's files.
DEFINES_FILE = "fr_defines.v"
#: A Verilog number literal given as text (``8'hff``, ``'b1010``, ``4'sd3``): taken as is.
_LITERAL = re.compile(r"\d*\s*'[sS]?[bodhBODH]\s*[0-9a-fA-FxXzZ_?]+")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_$]*")


def _verilog_value(what, name, value):
    """``value`` (a TOML value) as Verilog text: an integer, a boolean (1/0), a number
    literal given as text (``8'hff``) or any other text as a Verilog string."""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):
        if _LITERAL.fullmatch(value.strip()):
            return value.strip()
        if '"' in value or "\\" in value or "\n" in value:
            raise PortMapError(f"{what} {name}: a text value cannot hold '\"', '\\' or a newline")
        return f'"{value}"'
    raise PortMapError(
        f"{what} {name}: give a number, a boolean, a literal such as 8'hff or a text, got {value!r}"
    )


@dataclass(frozen=True)
class VerilogOverrides:
    """``parameters`` and ``defines``: ``((name, Verilog text), ...)``, sorted by name; a
    define without a value (``--define FAST``) has the text ``""``."""

    parameters: tuple = ()
    defines: tuple = ()

    @classmethod
    def of(cls, parameters=None, defines=None):
        """From ``{name: TOML value}`` dicts (a define's value may be ``True``: defined
        without a value); a bad name or value is a ``PortMapError``."""
        for what, names in (("--param", parameters or {}), ("--define", defines or {})):
            for name in names:
                if not _NAME.fullmatch(str(name)):
                    raise PortMapError(f"{what} {name!r}: not a Verilog identifier")
        return cls(
            tuple(
                (n, _verilog_value("--param", n, v)) for n, v in sorted((parameters or {}).items())
            ),
            tuple(
                (n, "" if v is True else _verilog_value("--define", n, v))
                for n, v in sorted((defines or {}).items())
            ),
        )

    def __bool__(self):
        return bool(self.parameters or self.defines)

    def define_text(self):
        """The ```define`` lines (``DEFINES_FILE``), or ``""`` without defines."""
        return "".join(f"`define {name} {text}\n" for name, text in self.defines)

    def with_defines(self, sources):
        """``sources`` (name -> text) with ``DEFINES_FILE`` first when there are defines."""
        if not self.defines:
            return dict(sources)
        return {DEFINES_FILE: self.define_text(), **sources}

    def instance(self):
        """The parameter overrides of the top's instance: ``#(.N(8)) `` or ``""``."""
        if not self.parameters:
            return ""
        return "#(" + ", ".join(f".{n}({t})" for n, t in self.parameters) + ") "

    def verilator_flags(self):
        """Verilator's ``-GNAME=VALUE`` for the top read alone."""
        return [f"-G{n}={t}" for n, t in self.parameters]

    def chparam(self, top):
        """Yosys's commands setting the parameters of ``top`` (before ``hierarchy``)."""
        return "".join(f"chparam -set {n} {t} {top}; " for n, t in self.parameters)

    def amaranth_params(self):
        """The parameters as ``Instance`` keyword arguments (``p_NAME``): an integer, a
        ``Const`` of a sized literal, a float or a text."""
        from amaranth.hdl import Const  # lazy: only the board build instantiates the top

        params = {}
        for name, text in self.parameters:
            literal = re.fullmatch(r"(\d*)\s*'([sS]?)([bodhBODH])\s*([0-9a-fA-F_]+)", text)
            if text.startswith('"'):
                value = text[1:-1]
            elif literal:
                width, _, base, digits = literal.groups()
                number = int(
                    digits.replace("_", ""), {"b": 2, "o": 8, "d": 10, "h": 16}[base.lower()]
                )
                value = Const(number, int(width or 32))
            elif re.fullmatch(r"-?\d+", text):
                value = int(text)
            else:
                try:
                    value = float(text)
                except ValueError:
                    raise PortMapError(
                        f"--param {name}={text}: the board build cannot set this value"
                    ) from None
            params[f"p_{name}"] = value
        return params

    def describe(self):
        """``SPEED=50, N=3; defines FAST`` for messages and summaries."""
        parts = [", ".join(f"{n}={t}" for n, t in self.parameters)] if self.parameters else []
        if self.defines:
            defs = ", ".join(f"{n}={t}" if t else n for n, t in self.defines)
            parts.append(f"defines {defs}")
        return "; ".join(parts)
